//! Exact integer max-min fair rates of flows sharing links, kept current as flows start and
//! end, at a cost that follows the rates that actually change.
//!
//! The allocation is defined by one procedure, progressive filling in whole bits per second:
//! repeatedly take the link with unfixed flows whose share `floor(capacity_left / unfixed)`
//! is smallest (ties to the lowest link index), fix its unfixed flows at `max(share, 1)`, and
//! take their rates from the capacity left on every link they cross (never below 0). Each
//! link that fixes flows does so at a *key* `(share, link)`; keys rise through the filling,
//! and a flow's key is its bottleneck link's. [`reference_rates`] runs that procedure plainly
//! over every link; it is the oracle the tests compare against.
//!
//! [`MaxMin::solve`] gives the same rates by replaying the filling only where it differs from
//! the last solve. A link's pop depends only on which of its flows are fixed before it and at
//! what rates, so a link none of whose flows changed pops at its old key and is not looked at.
//! The sweep walks keys upward through a heap of *dirty* links (their flow set changed, or a
//! flow on them got a new rate or key), each evaluated at the sweep's current key from its
//! flows: a flow settled in this sweep counts at its new rate, an untouched one at its old
//! rate if its old key has passed. A link counts them without visiting them: the flows the
//! sweep has drawn in (added, unsettled or fixed again) are tallied on every link they cross
//! as they change, and the untouched ones by group, the flows one link fixed last time (one
//! key, one rate), from the link's list of the groups crossing it and how many of each.
//! Flows whose bottleneck turned dirty are *unsettled*: if one is still unfixed when the sweep
//! passes its old key, every link it crosses turns dirty there (they would have counted it as
//! fixed). Before any link's old key is passed, every
//! way its pop could differ has marked it dirty, so untouched links and flows keep their old
//! keys and rates exactly.
//!
//! A flow keeps only its group: its rate and key are its group's link's. A group is drawn
//! in *whole* when its link turns dirty before any member was fixed alone elsewhere: its
//! members then share one sweep state, the group's (unfixed, then fixed at the link's pop),
//! so drawing it in, passing its old key and fixing it again each visit its links once, with
//! the count of members crossing each, and never a member; a member fixed alone by another
//! link takes a state of its own and leaves the group at the commit. A solve reports such a
//! group once, with its old rate ([`Changes::groups`]), and each flow fixed alone by itself.
//! A pop that must fix flows other than its group's finds them among the members of the groups
//! crossing its link that are not fixed yet, or among its flows when those are fewer. A dirty
//! link on which flows drawn in were fixed is not evaluated at once: a flow fixed at the
//! sweep's key takes no more than the share of any link it crosses that has not popped, so
//! their pops can only move later, and such a link is evaluated again when its entry comes up.
//!
//! Most links a changed flow crosses fixed nothing last time and fix nothing now; evaluating
//! each would cost more than the rest of the solve. Such a link (old key `NONE`, no flow
//! added) is only a *suspect*: the sweep runs as if it stays out of the filling, and then
//! checks it against the rates that sweep produced. If, walking its flows in key order, its
//! share always stays above the key of the next flow to be fixed, it never is the smallest
//! link during the filling, so leaving it out changed nothing; `capacity - load >= flows`
//! proves that without sorting (every share then exceeds each flow's rate by at least 1). A
//! suspect that fails is made dirty and the solve runs again from the same state. A link
//! that fixed nothing and only lost flows is not even a suspect: it gained room, so as long as
//! none of its other flows changes (which would note it), each share on its walk is at least
//! what it was.
//!
//! A flow removed when nothing else is pending, whose bottleneck fixed it alone and none of
//! whose other links fixed anything, needs no sweep at all: removing a flow only raises the
//! shares of the links it crosses, so none of them pops earlier, and its bottleneck simply
//! fixes nothing any more.
//!
//! A flow that removals leave alone on every link it crosses will run at the capacity, fixed
//! by its link of the lowest index; when that link fixed nothing last time it is made dirty as
//! the sweep begins, rather than left out and found by a failed check and a second sweep.
//!
//! Likewise a flow added when nothing else is pending, none of whose links fixed anything,
//! needs no sweep when the link leaving it the least room would fix it alone there and no
//! other link it crosses would come to fix anything (each checked by walking that link's
//! flows in key order, or by a slack certificate): the filling is the old one with that one
//! pop inserted. Most messages of a large sort-middle frame start on links no one else is
//! bottlenecked on.
//!
//! Must never use floating point, never iterate a hash map, and never depend on anything but
//! the flows' routes and the links' capacities (not on the order flows were added).

use std::cmp::Reverse;

use dary_heap::QuaternaryHeap;

use crate::net::LinkId;

/// `(share << link_bits) | link`: the order in which links fix their flows ([`Keys`]).
type Key = u64;

/// A link that fixed no flow (every flow on it was fixed before it), or a flow not yet rated.
const NONE: Key = Key::MAX;

/// How a key packs a share and a link: the link in the low `link_bits` bits, as few as the
/// network's links need, so that a key is one machine word (and a heap entry, a key and one
/// bit more, too). [`Keys::for_links`] says which capacities that leaves room for.
#[derive(Clone, Copy, Debug)]
struct Keys {
    link_bits: u32,
}

impl Keys {
    /// The packing for `links` links, if every share up to `capacity` bits per second fits
    /// (below `2^(63 - link_bits)`, so that no key reaches the heap's top bit or `NONE`);
    /// otherwise the largest capacity that would.
    fn for_links(links: usize, capacity: u64) -> Result<Keys, u64> {
        let link_bits = usize::BITS - links.saturating_sub(1).leading_zeros();
        let room = 63 - link_bits;
        match capacity >> room {
            0 => Ok(Keys { link_bits }),
            _ => Err((1u64 << room) - 1),
        }
    }

    fn key(self, share: u64, link: LinkId) -> Key {
        share << self.link_bits | link as Key
    }

    fn share_of(self, key: Key) -> u64 {
        key >> self.link_bits
    }

    fn link_of(self, key: Key) -> LinkId {
        (key & ((1 << self.link_bits) - 1)) as LinkId
    }

    /// The rate of the flows fixed at `key`; 0 for a flow not rated.
    fn rate_at(self, key: Key) -> u64 {
        match key {
            NONE => 0,
            k => self.share_of(k).max(1),
        }
    }
}

/// The fastest link, in bits per second, that the flow model can rate exactly on a network of
/// `links` links (its rates are whole bits per second, packed with a link's index in one
/// word): `Err` with that limit when `capacity` exceeds it.
pub fn fastest_link(links: usize, capacity: &Capacities) -> Result<(), u64> {
    Keys::for_links(links, capacity.max()).map(|_| ())
}

/// Each link's capacity in bits per second: one for every link, or one per link (a network
/// whose links differ, such as nodes of several processors on a faster switch).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Capacities {
    Uniform(u64),
    PerLink(Vec<u64>),
}

impl Capacities {
    pub fn of(&self, link: LinkId) -> u64 {
        match self {
            Capacities::Uniform(c) => *c,
            Capacities::PerLink(c) => c[link as usize],
        }
    }

    /// The largest capacity of any link.
    pub fn max(&self) -> u64 {
        match self {
            Capacities::Uniform(c) => *c,
            Capacities::PerLink(c) => c.iter().copied().max().unwrap_or(0),
        }
    }
}

/// What one [`MaxMin::solve`] changed.
#[derive(Default)]
pub struct Changes {
    /// `(slot, old rate)` of each flow whose rate or bottleneck changed on its own (rate 0
    /// for an added flow), in the order the filling fixed them.
    pub flows: Vec<(u32, u64)>,
    /// `(link, old rate)` of each group its link fixed again as one at a new rate: every
    /// member it kept has the new rate. A member that left it (fixed alone by another link)
    /// and a flow that joined it are in `flows`.
    pub groups: Vec<(LinkId, u64)>,
}

impl Changes {
    pub fn clear(&mut self) {
        self.flows.clear();
        self.groups.clear();
    }
}

/// Flows sharing links, and their max-min fair rates as of the last [`MaxMin::solve`].
pub struct MaxMin {
    capacity: Capacities,
    keys: Keys,
    links: Vec<Link>,
    flows: Vec<Flow>,
    /// Links that lost a flow since the last solve.
    shrunk: Vec<LinkId>,
    /// Suspects that failed their check in this solve: dirty from the start when it runs again.
    forced: Vec<LinkId>,
    /// Flows added since the last solve.
    added: Vec<u32>,
    /// `groups[l]`: the flows link `l` fixed in the last solve and the links they cross.
    groups: Vec<Group>,
    /// `group_entries[l]`: every group with a flow crossing link `l`, with how many cross it;
    /// a dirty link is evaluated from these (a handful) instead of from its flows.
    group_entries: Vec<Vec<GroupEntry>>,
    sweep: Sweep,
    /// The rates [`MaxMin::solve_from_scratch`] gave, flow by flow (the tests' oracle keeps
    /// no groups).
    #[cfg(test)]
    scratch_rates: Option<Vec<u64>>,
    /// Groups fixed again whole, and flows settled one by one.
    #[cfg(test)]
    settled_as: (u64, u64),
    /// Groups drawn in and fixed again whole as one, no member visited; of them, those some
    /// of whose members had been fixed alone elsewhere.
    #[cfg(test)]
    fixed_as_groups: (u64, u64),
    /// Pops that fixed their group alone and pops that walked their flows; of these, those
    /// that walked the members of the groups crossing them instead.
    #[cfg(test)]
    popped_as: (u64, u64),
    #[cfg(test)]
    walked_by_groups: u64,
    /// Evaluations put off until the link's entry came up (`SweepLink::stale`).
    #[cfg(test)]
    evaluated_late: u64,
    /// Whether a flow left alone on its links has its fixer made dirty as a sweep begins
    /// (`mark_fixer_of_freed`); off, the check after the sweep must find that link instead.
    #[cfg(test)]
    marks_freed_fixers: bool,
    /// Dirty-link evaluations, the flows and the groups crossing those links; flows drawn into
    /// a sweep and the links of their routes; solves that swept and sweeps run again because
    /// a suspect failed its check; flows added without a sweep (`fixer_if_added_alone`) and
    /// removed without one (`leaves_every_rate_as_it_is`); per sweep run, the links made
    /// dirty and the links left out of it and checked after it (suspects). Counted with the
    /// `counters` feature and in tests only.
    pub(super) evaluations: (u64, u64, u64),
    pub(super) swept: (u64, u64),
    pub(super) sweeps: (u64, u64),
    pub(super) alone: (u64, u64),
    pub(super) left_out: (u64, u64),
}

#[derive(Default)]
struct Link {
    flows: Vec<u32>,
    /// The sum of its flows' rates while two or more cross it. A link one flow crosses keeps
    /// none ([`MaxMin::load`] is that flow's rate), so that a sweep that changes the flow's
    /// rate need not visit it (`Sweep::lone`).
    load: u64,
}

/// The flows one link fixed in the last solve (all at its key, so at one rate), and the
/// links they cross with how many of them cross each. A change that befalls a whole group
/// (it is unsettled, passed or fixed again together) visits each of its links once, with the
/// count, instead of once per flow crossing it: the flows fixed by one link share most of
/// their routes.
#[derive(Default)]
struct Group {
    /// The members' slots, in no order (each flow knows its place: `Flow::member_at`), so
    /// that marking the link dirty or popping it visits its group, not every flow on it.
    slots: Vec<u32>,
    links: Vec<GroupLink>,
}

/// A link a group's flows cross: how many of them, and where the group's entry sits in
/// the link's `group_entries` (so a link the group stops crossing drops it without a search).
#[derive(Clone, Copy)]
struct GroupLink {
    link: LinkId,
    crossing: u32,
    entry: u32,
}

/// Group `group` crosses the link whose entry this is with `crossing` of its flows (the
/// count its `GroupLink` keeps too, `groups[group].links[at]`: a group's walk over its links
/// and a link's over its groups each read it where they are).
#[derive(Clone, Copy)]
struct GroupEntry {
    group: LinkId,
    at: u32,
    crossing: u32,
}

/// A flow: its group as of the last solve (its rate and key are the group's, so a group fixed
/// again whole at a new rate changes no member) and its own state in the current sweep, when
/// it has one (an added flow, or one fixed apart from its group), side by side in the first
/// cache line, its route after them.
#[repr(C, align(64))]
struct Flow {
    swept_key: Key,
    swept_rate: u64,
    swept_epoch: u64,
    /// The link that fixed it in the last solve; `NO_GROUP` before its first.
    group: LinkId,
    /// Its place in its group's `slots` (while it has a group).
    member_at: u32,
    settled: bool,
    live: bool,
    route: Vec<LinkId>,
}

/// A flow's group before its first solve.
const NO_GROUP: LinkId = LinkId::MAX;

impl Flow {
    fn swept(&self) -> SweepFlow {
        SweepFlow {
            epoch: self.swept_epoch,
            settled: self.settled,
            rate: self.swept_rate,
            key: self.swept_key,
        }
    }

    fn sweep_to(&mut self, s: SweepFlow) {
        self.swept_epoch = s.epoch;
        self.settled = s.settled;
        self.swept_rate = s.rate;
        self.swept_key = s.key;
    }
}

/// Per-solve state, and each link's key in the last solve beside it; `epoch` stamps what
/// belongs to the current solve.
#[derive(Default)]
struct Sweep {
    epoch: u64,
    /// Each link's record: its key in the last solve, its pop as last evaluated and its state
    /// in this solve, in one cache line (a visit to a link reads them together).
    links: Vec<SweepLink>,
    /// `unsettled[start..end]`: the flows a dirty link had fixed last time, when its group was
    /// not drawn in whole (one drawn in whole has no run: its members are in its state).
    unsettled_of: Vec<(u32, u32)>,
    dirty: Vec<LinkId>,
    /// Flows fixed one by one, and the dirty links that fixed their whole group again
    /// together (`SweepLink::fixed_whole`), in the order the filling fixed them.
    settled: Vec<u32>,
    settled_groups: Vec<LinkId>,
    /// Links left out of the filling, to be checked once it is done (`SweepLink::suspect`).
    suspects: Vec<LinkId>,
    /// Flows unsettled when a link turned dirty, in runs (`Sweep::unsettled_of`).
    unsettled: Vec<u32>,
    /// Dirty links to evaluate at `now` before the sweep moves on.
    pending: Vec<LinkId>,
    /// The flows a pop walks (`MaxMin::maybe_unfixed_on`).
    candidates: Vec<u32>,
    /// Min-heap of `key << 1 | kind`: kind 0 is a dirty link's pop as last evaluated (live
    /// while it equals the link's `pop`), kind 1 passes the old key of a dirty link whose
    /// flows were unsettled. At one key, a pop comes before a pass.
    heap: QuaternaryHeap<Reverse<u64>>,
    /// The key of the last link that fixed flows or of the last old key passed.
    now: Key,
    /// The untouched flows a link will see fixed as the sweep rises, as (old key, old rate,
    /// how many).
    ahead: Vec<Ahead>,
    /// Lone links are left out of this sweep (`Sweep::lone`): set once its first dirty links
    /// are marked, on a network whose links have one capacity.
    skip_lone: bool,
}

/// Flows a link sees fixed elsewhere at one key: `(key, rate, count)`.
type Ahead = (Key, u64, u64);

/// A flow's state in one sweep (kept in [`Flow`]).
#[derive(Clone, Copy)]
struct SweepFlow {
    epoch: u64,
    settled: bool,
    rate: u64,
    key: Key,
}

/// What a visit to a link reads, packed into one cache line: settling a flow visits every
/// link it crosses.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct SweepLink {
    /// Its key in the last solve (`NONE` if it fixed nothing): kept from solve to solve, the
    /// one field here that is not the current sweep's.
    key: Key,
    /// Where it pops, as last evaluated while dirty; `NONE` if it fixes nothing as things
    /// stand.
    pop: Key,
    /// Equal to the sweep's epoch while the link is dirty in this solve.
    epoch: u64,
    /// `suspect` and `delta` belong to the solve of this epoch.
    seen: u64,
    /// How much the flows settled in this sweep add to its load.
    delta: i64,
    /// Of its flows drawn into this sweep (added, unsettled or fixed again), the rates of
    /// those fixed and how many are not fixed yet.
    drawn_load: u64,
    drawn_unfixed: u32,
    /// Of the flows it fixed last time (its group), how many have a sweep state of their
    /// own: fixed one by one by some link (or, for a group not drawn in whole, drawn in).
    drawn_alone: u32,
    /// It fixed its flows; nothing can change it any more in this solve.
    popped: bool,
    pending: bool,
    suspect: bool,
    /// Dirty, with its group drawn in whole: a member with no sweep state of its own is in
    /// the group's, unfixed until `fixed_whole`, then fixed at the link's pop.
    whole: bool,
    fixed_whole: bool,
    /// Dirty, and flows drawn in on it were fixed since it was last evaluated: fixing a flow at
    /// the sweep's key only raises the shares of the other links it crosses, so its pop can
    /// only have moved later, and it is evaluated again when its entry comes up, not at once.
    stale: bool,
    /// Exactly one flow crosses it (kept from solve to solve, like `key`): read where the
    /// link's other fields are, so that leaving a lone link out reads nothing more.
    single: bool,
}

const _: () = assert!(std::mem::size_of::<SweepLink>() == 64);

impl Default for SweepLink {
    fn default() -> SweepLink {
        SweepLink {
            key: NONE,
            pop: NONE,
            epoch: 0,
            seen: 0,
            delta: 0,
            drawn_unfixed: 0,
            drawn_load: 0,
            drawn_alone: 0,
            popped: false,
            pending: false,
            suspect: false,
            whole: false,
            fixed_whole: false,
            stale: false,
            single: false,
        }
    }
}

const POP: u64 = 0;
const PASS: u64 = 1;

impl Sweep {
    /// Whether `link` is left out of this sweep altogether (*lone*): one flow crosses it, it
    /// fixed nothing last time, and it is not dirty. A link that fixed nothing turns dirty
    /// only as a sweep begins, so nothing ever reads what it would tally; with one flow on
    /// it, it still fixes nothing unless that flow's rate reaches the link's capacity, which
    /// is checked once the sweep is done (`MaxMin::lone_links_stay_out`). On a 512-node Delta
    /// frame more than half the links a sweep would leave out and check after it are lone: a
    /// message's route crosses links no other message is using.
    #[inline]
    fn lone(&self, link: LinkId) -> bool {
        let sl = &self.links[link as usize];
        self.skip_lone && sl.single && sl.key == NONE && sl.epoch != self.epoch
    }

    /// Whether `link` is dirty in this sweep (so the flows it fixed last time, its group, are
    /// all drawn in).
    fn is_dirty(&self, link: LinkId) -> bool {
        self.links[link as usize].epoch == self.epoch
    }

    /// `link`'s tallies of the flows drawn into this sweep: how many are unfixed, and the sum
    /// of the rates of those fixed.
    fn drawn_on(&self, link: LinkId) -> (u32, u64) {
        let sl = &self.links[link as usize];
        match sl.seen == self.epoch {
            true => (sl.drawn_unfixed, sl.drawn_load),
            false => (0, 0),
        }
    }

    /// `link`'s per-solve state, with its suspect mark and load delta reset on first use in
    /// this epoch.
    fn link_seen(&mut self, link: LinkId) -> &mut SweepLink {
        let sl = &mut self.links[link as usize];
        if sl.seen != self.epoch {
            sl.seen = self.epoch;
            sl.suspect = false;
            sl.delta = 0;
            sl.drawn_unfixed = 0;
            sl.drawn_load = 0;
            sl.drawn_alone = 0;
        }
        sl
    }

    /// How many of `link`'s group have a sweep state of their own.
    fn drawn_alone(&self, link: LinkId) -> u32 {
        let sl = &self.links[link as usize];
        match sl.seen == self.epoch {
            true => sl.drawn_alone,
            false => 0,
        }
    }

    /// Whether `link` is dirty with its group drawn in whole.
    fn drawn_whole(&self, link: LinkId) -> bool {
        let sl = &self.links[link as usize];
        sl.epoch == self.epoch && sl.whole
    }

    /// `flows` more flows crossing `link` are drawn in unfixed; a dirty link that has not
    /// fixed its flows is evaluated again.
    #[inline]
    fn count_drawn(&mut self, link: LinkId, flows: u32) {
        let epoch = self.epoch;
        let sl = self.link_seen(link);
        sl.drawn_unfixed += flows;
        if sl.epoch == epoch && !sl.popped && !sl.pending {
            sl.pending = true;
            self.pending.push(link);
        }
    }
}

impl MaxMin {
    /// `links` links of the given capacities, none faster than [`fastest_link`] allows (the
    /// network refuses a faster one before building its model).
    pub fn new(capacity: Capacities, links: usize) -> MaxMin {
        let keys = Keys::for_links(links, capacity.max())
            .expect("link capacities within what the flow model's keys hold");
        MaxMin {
            capacity,
            keys,
            links: (0..links).map(|_| Link::default()).collect(),
            groups: (0..links).map(|_| Group::default()).collect(),
            group_entries: vec![Vec::new(); links],
            flows: Vec::new(),
            shrunk: Vec::new(),
            forced: Vec::new(),
            added: Vec::new(),
            #[cfg(test)]
            scratch_rates: None,
            #[cfg(test)]
            settled_as: (0, 0),
            #[cfg(test)]
            fixed_as_groups: (0, 0),
            #[cfg(test)]
            popped_as: (0, 0),
            #[cfg(test)]
            walked_by_groups: 0,
            #[cfg(test)]
            evaluated_late: 0,
            #[cfg(test)]
            marks_freed_fixers: true,
            evaluations: (0, 0, 0),
            swept: (0, 0),
            sweeps: (0, 0),
            alone: (0, 0),
            left_out: (0, 0),
            sweep: Sweep {
                links: vec![SweepLink::default(); links],
                unsettled_of: vec![(0, 0); links],
                ..Sweep::default()
            },
        }
    }

    /// Adds flow `slot` (not present) on `route`; it has no rate until the next solve.
    pub fn add(&mut self, slot: u32, route: &[LinkId]) {
        let i = slot as usize;
        if i >= self.flows.len() {
            self.flows.resize_with(i + 1, || Flow {
                swept_key: NONE,
                swept_rate: 0,
                swept_epoch: 0,
                group: NO_GROUP,
                member_at: 0,
                settled: false,
                live: false,
                route: Vec::new(),
            });
        }
        let f = &mut self.flows[i];
        f.route.clear();
        f.route.extend_from_slice(route);
        f.group = NO_GROUP;
        f.live = true;
        for &l in route {
            let flows = &mut self.links[l as usize].flows;
            flows.push(slot);
            let (count, first) = (flows.len(), flows[0]);
            if count == 2 {
                // It kept no load with one flow; the new flow has no rate yet.
                self.links[l as usize].load = self.old_rate(first);
            }
            self.sweep.links[l as usize].single = count == 1;
        }
        self.added.push(slot);
    }

    /// Removes flow `slot`; the others' rates change at the next solve.
    pub fn remove(&mut self, slot: u32) {
        let old = self.old_key(slot);
        let alone = self.leaves_every_rate_as_it_is(slot);
        if old != NONE {
            self.leave(slot, self.keys.link_of(old));
        }
        let rate = self.keys.rate_at(old);
        #[cfg(test)]
        if let Some(r) = self
            .scratch_rates
            .as_mut()
            .and_then(|r| r.get_mut(slot as usize))
        {
            *r = 0;
        }
        let f = &mut self.flows[slot as usize];
        f.group = NO_GROUP;
        f.live = false;
        for &l in &f.route {
            let link = &mut self.links[l as usize];
            let pos = link
                .flows
                .iter()
                .position(|&x| x == slot)
                .expect("flow on its link");
            link.flows.swap_remove(pos);
            // With one flow left, or none, the link keeps no load.
            link.load = match link.flows.len() {
                0 | 1 => 0,
                _ => link.load - rate,
            };
            self.sweep.links[l as usize].single = link.flows.len() == 1;
        }
        if alone {
            self.sweep.links[self.keys.link_of(old) as usize].key = NONE;
            #[cfg(any(test, feature = "counters"))]
            {
                self.alone.1 += 1;
            }
        } else {
            self.shrunk.extend_from_slice(&f.route);
        }
    }

    /// Whether removing flow `slot` from the last solve's state changes no other flow's rate:
    /// nothing else is pending, its bottleneck fixed it alone, and no other link it crosses
    /// fixed anything. Removing a flow only raises the shares of the links it crosses, so
    /// those that fixed nothing still fix nothing, and no other link's pop can move; its
    /// bottleneck is left with no flow to fix.
    fn leaves_every_rate_as_it_is(&self, slot: u32) -> bool {
        let f = &self.flows[slot as usize];
        if f.group == NO_GROUP || !(self.added.is_empty() && self.shrunk.is_empty()) {
            return false;
        }
        let g = f.group;
        self.groups[g as usize].slots.len() == 1
            && f.route.iter().all(|&l| l == g || self.last_key(l) == NONE)
    }

    /// If adding flow `slot` (the only change since the last solve) leaves every other rate
    /// as it is, the key at which it is fixed. That holds when none of its links fixed
    /// anything and, with the link `b` that leaves it the least room fixing it alone at that
    /// room: `b`'s other flows are all fixed (by other links) before its share, with the new
    /// flow counted, falls to theirs, and no other link's share, with the new flow counted
    /// until `b` fixes it and at its rate after, ever falls to that of the next flow it sees
    /// fixed. The filling is then the old one with `b`'s pop inserted in key order.
    fn fixer_if_added_alone(&mut self, slot: u32) -> Option<Key> {
        let f = &self.flows[slot as usize];
        if !f.live {
            return None;
        }
        let mut fixer = NONE;
        for &l in &f.route {
            if self.last_key(l) != NONE {
                return None;
            }
            let room = self.capacity.of(l).saturating_sub(self.load(l));
            fixer = fixer.min(self.keys.key(room, l));
        }
        let b = self.keys.link_of(fixer);
        if !self.fixes_only_the_added(b, slot, fixer) {
            return None;
        }
        for i in 0..self.flows[slot as usize].route.len() {
            let l = self.flows[slot as usize].route[i];
            if l != b && !self.stays_out_with_added(l, slot, fixer) {
                return None;
            }
        }
        Some(fixer)
    }

    /// Whether link `b`, gaining flow `slot`, fixes it alone at key `at`: walking its other
    /// flows in key order with `slot` counted unfixed, its share stays above the next one's
    /// key (at the last step a share of `(room + rate) / 2` above it puts `at`, the room,
    /// above it too). With room of at least their largest rate plus their count plus one,
    /// every share on the walk exceeds the next flow's rate, so no sort is needed.
    fn fixes_only_the_added(&mut self, b: LinkId, slot: u32, at: Key) -> bool {
        let room = self.keys.share_of(at);
        let flows = &self.links[b as usize].flows;
        let others = flows.len() as u64 - 1;
        let largest = flows
            .iter()
            .filter(|&&s| s != slot)
            .map(|&s| self.old_rate(s))
            .max()
            .unwrap_or(0);
        if room > largest + others {
            return true;
        }
        let mut ahead = std::mem::take(&mut self.sweep.ahead);
        ahead.clear();
        ahead.extend(flows.iter().filter(|&&s| s != slot).map(|&s| {
            let key = self.old_key(s);
            (key, self.keys.rate_at(key), 1)
        }));
        let alone = share_stays_above(self.keys, self.capacity.of(b), b, &mut ahead, 1);
        self.sweep.ahead = ahead;
        alone
    }

    /// Whether link `l`, which fixed nothing, still fixes nothing once flow `slot` on it is
    /// fixed at key `at` (elsewhere). Alone on it, the flow is fixed by a link with no more
    /// room, ties to the lower index; with slack for every flow, `stays_out`'s certificate;
    /// otherwise its walk.
    fn stays_out_with_added(&mut self, l: LinkId, slot: u32, at: Key) -> bool {
        let rate = self.keys.share_of(at).max(1);
        let link = &self.links[l as usize];
        if link.flows.len() == 1
            || self.load(l) + rate + link.flows.len() as u64 <= self.capacity.of(l)
        {
            return true;
        }
        let mut ahead = std::mem::take(&mut self.sweep.ahead);
        ahead.clear();
        ahead.extend(link.flows.iter().map(|&s| match s == slot {
            true => (at, rate, 1),
            false => (self.old_key(s), self.old_rate(s), 1),
        }));
        let out = share_stays_above(self.keys, self.capacity.of(l), l, &mut ahead, 0);
        self.sweep.ahead = ahead;
        out
    }

    /// Commits flow `slot`, added alone, as fixed by its link `b` alone at key `at`.
    fn fix_added_alone(&mut self, slot: u32, at: Key, changes: &mut Changes) {
        let rate = self.keys.share_of(at).max(1);
        changes.flows.push((slot, 0));
        let f = &mut self.flows[slot as usize];
        f.group = self.keys.link_of(at);
        for &l in &f.route {
            // A link it alone crosses keeps no load: its rate is the flow's, set below.
            let link = &mut self.links[l as usize];
            if link.flows.len() > 1 {
                link.load += rate;
            }
        }
        self.sweep.links[self.keys.link_of(at) as usize].key = at;
        self.join(slot, self.keys.link_of(at));
        #[cfg(any(test, feature = "counters"))]
        {
            self.alone.0 += 1;
        }
    }

    /// Flow `slot` becomes one of the flows link `g` fixes. Into an empty group its links go
    /// without a search.
    fn join(&mut self, slot: u32, g: LinkId) {
        let group = &mut self.groups[g as usize];
        let fresh = group.slots.is_empty();
        self.flows[slot as usize].member_at = group.slots.len() as u32;
        group.slots.push(slot);
        for &l in &self.flows[slot as usize].route {
            let entries = &mut self.group_entries[l as usize];
            // A new group's entries are the last of their links' lists.
            let found = match fresh {
                true => entries.last_mut().filter(|e| e.group == g),
                false => entries.iter_mut().find(|e| e.group == g),
            };
            match found {
                Some(e) => {
                    e.crossing += 1;
                    group.links[e.at as usize].crossing += 1;
                }
                None => {
                    entries.push(GroupEntry {
                        group: g,
                        at: group.links.len() as u32,
                        crossing: 1,
                    });
                    group.links.push(GroupLink {
                        link: l,
                        crossing: 1,
                        entry: entries.len() as u32 - 1,
                    });
                }
            }
        }
    }

    /// Flow `slot` stops being one of the flows link `g` fixes. The last member takes the
    /// group's links with it without a search: they are its route's.
    fn leave(&mut self, slot: u32, g: LinkId) {
        let group = &mut self.groups[g as usize];
        let at = self.flows[slot as usize].member_at as usize;
        group.slots.swap_remove(at);
        if let Some(&moved) = group.slots.get(at) {
            self.flows[moved as usize].member_at = at as u32;
        }
        if group.slots.is_empty() {
            let mut links = std::mem::take(&mut group.links);
            for gl in links.drain(..) {
                self.drop_entry(gl.link, gl.entry);
            }
            self.groups[g as usize].links = links;
            return;
        }
        for j in 0..self.flows[slot as usize].route.len() {
            let l = self.flows[slot as usize].route[j];
            let entries = &mut self.group_entries[l as usize];
            let e = entries
                .iter()
                .position(|e| e.group == g)
                .expect("a member's link is in its group");
            entries[e].crossing -= 1;
            let i = entries[e].at as usize;
            let group = &mut self.groups[g as usize];
            group.links[i].crossing -= 1;
            if entries[e].crossing > 0 {
                continue;
            }
            group.links.swap_remove(i);
            if let Some(&moved) = group.links.get(i) {
                self.group_entries[moved.link as usize][moved.entry as usize].at = i as u32;
            }
            self.drop_entry(l, e as u32);
        }
    }

    /// Removes entry `e` of `link`'s `group_entries`, repointing the group whose entry moves
    /// into its place.
    fn drop_entry(&mut self, link: LinkId, e: u32) {
        let entries = &mut self.group_entries[link as usize];
        entries.swap_remove(e as usize);
        if let Some(moved) = entries.get(e as usize) {
            self.groups[moved.group as usize].links[moved.at as usize].entry = e;
        }
    }

    /// Flows on `link` now.
    pub fn flows_on(&self, link: LinkId) -> usize {
        self.links[link as usize].flows.len()
    }

    /// The links flow `slot` crosses.
    pub fn route(&self, slot: u32) -> &[LinkId] {
        &self.flows[slot as usize].route
    }

    /// The rate of flow `slot` as of the last solve (0 before its first).
    #[cfg(test)]
    pub fn rate(&self, slot: u32) -> u64 {
        match &self.scratch_rates {
            Some(rates) => rates[slot as usize],
            None => self.old_rate(slot),
        }
    }

    /// The sum of the rates of the flows on `link` as of the last solve.
    #[inline]
    fn load(&self, link: LinkId) -> u64 {
        let l = &self.links[link as usize];
        match l.flows[..] {
            [only] => self.old_rate(only),
            _ => l.load,
        }
    }

    /// Link `link`'s key in the last solve; `NONE` if it fixed nothing.
    fn last_key(&self, link: LinkId) -> Key {
        self.sweep.links[link as usize].key
    }

    /// Flow `slot`'s key as of the last solve (its group's); `NONE` before its first.
    fn old_key(&self, slot: u32) -> Key {
        match self.flows[slot as usize].group {
            NO_GROUP => NONE,
            g => self.last_key(g),
        }
    }

    fn old_rate(&self, slot: u32) -> u64 {
        self.keys.rate_at(self.old_key(slot))
    }

    /// The link that fixes flow `slot` (its bottleneck) as of the last solve. Every flow one
    /// link fixes has the same rate ([`MaxMin::group_rate`]).
    pub fn bottleneck(&self, slot: u32) -> LinkId {
        self.flows[slot as usize].group
    }

    /// The flows link `g` fixed in the last solve, in no order.
    #[cfg(any(test, feature = "counters"))]
    pub fn members(&self, g: LinkId) -> &[u32] {
        &self.groups[g as usize].slots
    }

    /// `changes` (of the last solve) flow by flow: `(slot, old rate)` of every flow whose rate
    /// or bottleneck changed, each once.
    #[cfg(any(test, feature = "counters"))]
    pub fn flow_by_flow(&self, changes: &Changes) -> Vec<(u32, u64)> {
        let alone: std::collections::BTreeSet<u32> = changes.flows.iter().map(|c| c.0).collect();
        let mut all = changes.flows.clone();
        for &(g, old) in &changes.groups {
            let joined_before = self.members(g).iter().filter(|s| !alone.contains(s));
            all.extend(joined_before.map(|&s| (s, old)));
        }
        all
    }

    /// The rate of the flows link `g` fixed in the last solve; `None` if it fixed none.
    pub fn group_rate(&self, g: LinkId) -> Option<u64> {
        (!self.groups[g as usize].slots.is_empty())
            .then(|| self.keys.share_of(self.last_key(g)).max(1))
    }

    /// Brings every rate up to date with the adds and removes since the last solve, and
    /// appends to `changes` every flow whose rate or bottleneck changed: one by one, or as a
    /// group fixed again whole at a new rate. Never inlined: it is large and called from one
    /// place, where inlining it only crowds its caller (one polio frame measured 1.3% more
    /// instructions with it inlined).
    #[inline(never)]
    pub fn solve(&mut self, changes: &mut Changes) {
        match (&self.added[..], &self.shrunk[..]) {
            // Nothing since the last solve but removals that moved no other rate.
            ([], []) => return,
            (&[slot], []) => {
                if let Some(fixer) = self.fixer_if_added_alone(slot) {
                    self.fix_added_alone(slot, fixer, changes);
                    self.added.clear();
                    return;
                }
            }
            _ => {}
        }
        #[cfg(any(test, feature = "counters"))]
        {
            self.sweeps.0 += 1;
        }
        while !self.sweep_and_check() {
            #[cfg(any(test, feature = "counters"))]
            {
                self.sweeps.1 += 1;
            }
        }
        self.commit(changes);
        self.added.clear();
        self.shrunk.clear();
        self.forced.clear();
    }

    /// One sweep from the last solve's state; false if a suspect failed its check (it is
    /// then in `forced`, and nothing was committed).
    fn sweep_and_check(&mut self) -> bool {
        let s = &mut self.sweep;
        s.epoch += 1;
        s.now = 0;
        s.dirty.clear();
        s.settled.clear();
        s.settled_groups.clear();
        s.unsettled.clear();
        s.suspects.clear();
        s.heap.clear();
        s.skip_lone = false;
        #[cfg(any(test, feature = "counters"))]
        for &slot in &self.added {
            self.swept.0 += 1;
            self.swept.1 += self.flows[slot as usize].route.len() as u64;
        }
        for i in 0..self.added.len() {
            let slot = self.added[i];
            let epoch = self.sweep.epoch;
            let f = &mut self.flows[slot as usize];
            if f.swept_epoch == epoch {
                continue; // added twice (removed and added again before this solve)
            }
            f.sweep_to(SweepFlow {
                epoch,
                settled: false,
                rate: 0,
                key: NONE,
            });
            if f.live {
                for j in 0..f.route.len() {
                    let l = self.flows[slot as usize].route[j];
                    self.sweep.link_seen(l).drawn_unfixed += 1;
                }
            }
        }
        for i in 0..self.forced.len() {
            self.mark_dirty(self.forced[i]);
        }
        for i in 0..self.added.len() {
            self.mark_fixer_of_added(self.added[i]);
        }
        // Lone links, and the freed flows' fixers among them, exist on one link capacity only.
        let uniform = matches!(self.capacity, Capacities::Uniform(_));
        if uniform {
            for i in 0..self.shrunk.len() {
                self.mark_fixer_of_freed(self.shrunk[i]);
            }
        }
        // No link that fixed nothing turns dirty from here on.
        self.sweep.skip_lone = uniform;
        for i in 0..self.added.len() {
            self.note_route(self.added[i]);
        }
        for i in 0..self.shrunk.len() {
            // A link that fixed nothing only gained room when a flow left it, so it still fixes
            // nothing unless a flow on it gets another rate or key, and that notes it then.
            let link = self.shrunk[i];
            if self.last_key(link) != NONE {
                self.mark_dirty(link);
            }
        }
        self.evaluate_pending();
        while let Some(Reverse(entry)) = self.sweep.heap.pop() {
            let at = entry >> 1;
            let link = self.keys.link_of(at);
            if entry & 1 == POP {
                let sl = &self.sweep.links[link as usize];
                if self.sweep.links[link as usize].pop == at && !sl.popped {
                    match sl.stale {
                        true => {
                            self.evaluate(link);
                            #[cfg(test)]
                            {
                                self.evaluated_late += 1;
                            }
                            #[cfg(test)]
                            assert!(
                                self.sweep.links[link as usize].pop >= at,
                                "link {link}'s pop moved earlier while it waited"
                            );
                        }
                        false => self.pop(link, at),
                    }
                }
            } else {
                self.pass_old_key(link, at);
            }
            self.evaluate_pending();
        }
        #[cfg(any(test, feature = "counters"))]
        {
            self.left_out.0 += self.sweep.dirty.len() as u64;
            self.left_out.1 += self.sweep.suspects.len() as u64;
        }
        let forced = self.forced.len();
        for i in 0..self.sweep.suspects.len() {
            let link = self.sweep.suspects[i];
            if !self.sweep.is_dirty(link) && !self.stays_out(link) {
                self.forced.push(link);
            }
        }
        if self.sweep.skip_lone {
            self.lone_links_stay_out();
        }
        self.forced.len() == forced
    }

    /// Added flow `slot`'s links gained it. All are noted as the sweep begins (a link that
    /// fixed flows last time turns dirty, one that fixed none is a suspect); here the suspects
    /// likely to fail their check are made dirty instead, saving a second sweep: those whose
    /// load would come within its flow count of the capacity if the new flow took as much as
    /// its tightest link leaves room for. And one link must be dirty to fix the new flow: if
    /// no other is, its tightest link is. Which links are dirty only changes the cost: a
    /// suspect that should have fixed flows fails its check and the sweep runs again.
    fn mark_fixer_of_added(&mut self, slot: u32) {
        let f = &self.flows[slot as usize];
        if !f.live {
            return; // removed again before this solve: `shrunk` holds its links
        }
        // A guess at the new flow's rate: the most it could get on its tightest link.
        let mut guess = u64::MAX;
        let mut tightest = None;
        for &l in &f.route {
            let link = &self.links[l as usize];
            let capacity = self.capacity.of(l);
            let share = capacity / link.flows.len() as u64;
            let room = capacity.saturating_sub(self.load(l)).max(share);
            if room < guess {
                guess = room;
                tightest = Some(l);
            }
        }
        let mut fixer = tightest;
        for i in 0..self.flows[slot as usize].route.len() {
            let l = self.flows[slot as usize].route[i];
            let link = &self.links[l as usize];
            if self.last_key(l) != NONE {
                fixer = None;
            } else if self.load(l) + guess + link.flows.len() as u64 > self.capacity.of(l) {
                self.mark_dirty(l);
                fixer = None;
            }
        }
        if let Some(l) = fixer {
            self.mark_dirty(l);
        }
    }

    /// `link` lost a flow. If it kept one, and that flow now crosses no link another crosses,
    /// it will run at the links' one capacity, fixed by its link of the lowest index (every
    /// share is the capacity, and ties go to the lowest link). When that link fixed nothing
    /// last time, the sweep would leave it out as lone, and its check after the sweep would
    /// fail and run the sweep again (most second sweeps of a 512-node Delta frame, where a
    /// message that shared a link with another is left alone when that one ends); it is made
    /// dirty now instead. Which links are dirty only changes the cost. On a network of one
    /// link capacity only (the caller's test).
    fn mark_fixer_of_freed(&mut self, link: LinkId) {
        #[cfg(test)]
        if !self.marks_freed_fixers {
            return;
        }
        let &[slot] = &self.links[link as usize].flows[..] else {
            return;
        };
        // The link that fixed the flow had another flow on it, so it lost one: the flow's
        // route is walked once, for that link, however many it shared with the flows gone.
        if self.flows[slot as usize].group != link {
            return;
        }
        let mut lowest = link;
        for &l in &self.flows[slot as usize].route {
            if self.links[l as usize].flows.len() != 1 {
                return;
            }
            lowest = lowest.min(l);
        }
        if self.last_key(lowest) == NONE {
            self.mark_dirty(lowest);
        }
    }

    /// A flow on `link` changed: a link that fixed flows last time is dirty, one that fixed
    /// none is a suspect.
    #[inline]
    fn note(&mut self, link: LinkId) {
        if self.last_key(link) != NONE {
            // Most notes find the link dirty already: that test stays out of the call.
            if !self.sweep.is_dirty(link) {
                self.mark_dirty(link);
            }
            return;
        }
        if self.sweep.lone(link) {
            return;
        }
        let epoch = self.sweep.epoch;
        let sl = self.sweep.link_seen(link);
        if sl.epoch != epoch && !sl.suspect {
            sl.suspect = true;
            self.sweep.suspects.push(link);
        }
    }

    /// Puts in `forced` every lone link (`Sweep::lone`: left out of this sweep) that would
    /// have fixed its flow. Its one flow was drawn in (nothing else changes a lone link), and
    /// every flow drawn in crosses a dirty link, so it is fixed; the link stays out while the
    /// flow's rate is below the link's capacity, the one capacity of every link here. Only a
    /// flow as fast as a link can be has its lone links checked, as a suspect is.
    fn lone_links_stay_out(&mut self) {
        let capacity = self.capacity.max();
        for i in 0..self.sweep.settled.len() {
            let slot = self.sweep.settled[i];
            let sf = self.flows[slot as usize].swept();
            if sf.rate >= capacity {
                self.force_lone_links_of(slot, sf.rate, sf.key);
            }
        }
        for i in 0..self.sweep.settled_groups.len() {
            let g = self.sweep.settled_groups[i];
            let at = self.sweep.links[g as usize].pop;
            if self.keys.rate_at(at) < capacity {
                continue;
            }
            for j in 0..self.groups[g as usize].slots.len() {
                let slot = self.groups[g as usize].slots[j];
                if let Some((rate, key)) = self.final_rate_and_key(slot) {
                    self.force_lone_links_of(slot, rate, key);
                }
            }
        }
        for i in 0..self.added.len() {
            let slot = self.added[i];
            let f = &self.flows[slot as usize];
            if f.live && !f.settled {
                // Never so (see above); were it, its lone links would fix it.
                self.force_lone_links_of(slot, 0, NONE);
            }
        }
    }

    /// Puts in `forced` each lone link of flow `slot`, fixed at `rate` (the links' capacity:
    /// a slower flow leaves them all out) and `key` in this sweep (`NONE`: not fixed), that
    /// would have fixed it: `stays_out`'s walk, with the flow alone on the link.
    fn force_lone_links_of(&mut self, slot: u32, rate: u64, key: Key) {
        for j in 0..self.flows[slot as usize].route.len() {
            let l = self.flows[slot as usize].route[j];
            if !self.sweep.lone(l) {
                continue;
            }
            let capacity = self.capacity.of(l);
            let out =
                key != NONE && share_stays_above(self.keys, capacity, l, &mut [(key, rate, 1)], 0);
            if !out {
                self.forced.push(l);
            }
        }
    }

    /// Whether suspect `link`, left out of this sweep, would have fixed nothing in it: as its
    /// flows are fixed in key order at the rates the sweep gave them, its share never falls
    /// to the key of the next one.
    fn stays_out(&mut self, link: LinkId) -> bool {
        let l = &self.links[link as usize];
        let load = self.load(link) as i128 + self.sweep.links[link as usize].delta as i128;
        if load + l.flows.len() as i128 <= self.capacity.of(link) as i128 {
            return true;
        }
        let mut ahead = std::mem::take(&mut self.sweep.ahead);
        ahead.clear();
        for &slot in &l.flows {
            match self.final_rate_and_key(slot) {
                Some((rate, key)) => ahead.push((key, rate, 1)),
                None => {
                    self.sweep.ahead = ahead;
                    return false;
                }
            }
        }
        let out = share_stays_above(self.keys, self.capacity.of(link), link, &mut ahead, 0);
        self.sweep.ahead = ahead;
        out
    }

    /// Flow `slot`'s rate and key once this sweep is done; None if nothing fixed it.
    fn final_rate_and_key(&self, slot: u32) -> Option<(u64, Key)> {
        if let Some(sf) = self.swept_state(slot) {
            return sf.settled.then_some((sf.rate, sf.key));
        }
        let key = self.old_key(slot);
        (key != NONE).then_some((self.keys.rate_at(key), key))
    }

    /// Flow `slot`'s state in this sweep if it is drawn in: its own, or its group's when its
    /// group is drawn in whole.
    fn swept_state(&self, slot: u32) -> Option<SweepFlow> {
        let f = &self.flows[slot as usize];
        let epoch = self.sweep.epoch;
        if f.swept_epoch == epoch {
            return Some(f.swept());
        }
        let g = f.group;
        if g == NO_GROUP || !self.sweep.drawn_whole(g) {
            return None;
        }
        let settled = self.sweep.links[g as usize].fixed_whole;
        let key = match settled {
            true => self.sweep.links[g as usize].pop,
            false => self.last_key(g),
        };
        Some(SweepFlow {
            epoch,
            settled,
            rate: self.keys.rate_at(key),
            key,
        })
    }

    /// Makes `link` part of the sweep (once): it will be evaluated, and the flows it fixed
    /// last time are unsettled until something fixes them again. A group none of whose
    /// members is drawn in yet is drawn in whole, as one: its links once each, with the count
    /// crossing each, and no member visited.
    fn mark_dirty(&mut self, link: LinkId) {
        let l = link as usize;
        let epoch = self.sweep.epoch;
        if self.sweep.links[l].epoch == epoch {
            return;
        }
        let old = self.last_key(link);
        debug_assert!(
            old >= self.sweep.now,
            "link {link} turned dirty after its old key had passed"
        );
        let members = self.groups[l].slots.len();
        // The flows it fixed last time are its group (a link that fixed nothing has none).
        // None of them can be drawn in yet but those another link fixed (`fix`).
        let whole = members > 0 && self.sweep.drawn_alone(link) == 0;
        let start = self.sweep.unsettled.len() as u32;
        if whole {
            #[cfg(any(test, feature = "counters"))]
            {
                self.swept.0 += members as u64;
                let crossings = self.groups[l].links.iter().map(|gl| gl.crossing as u64);
                self.swept.1 += crossings.sum::<u64>();
            }
            for gl in &self.groups[l].links {
                if !self.sweep.lone(gl.link) {
                    self.sweep.count_drawn(gl.link, gl.crossing);
                }
            }
        } else {
            for i in 0..members {
                let slot = self.groups[l].slots[i];
                let f = &mut self.flows[slot as usize];
                if f.swept_epoch != epoch {
                    #[cfg(any(test, feature = "counters"))]
                    {
                        self.swept.0 += 1;
                        self.swept.1 += f.route.len() as u64;
                    }
                    f.sweep_to(SweepFlow {
                        epoch,
                        settled: false,
                        rate: self.keys.rate_at(old),
                        key: old,
                    });
                    self.sweep.unsettled.push(slot);
                }
            }
            for i in start..self.sweep.unsettled.len() as u32 {
                let slot = self.sweep.unsettled[i as usize];
                self.draw_route(slot);
            }
        }
        let end = self.sweep.unsettled.len() as u32;
        self.sweep.unsettled_of[l] = (start, end);
        self.sweep.links[l] = SweepLink {
            epoch,
            pop: NONE,
            popped: false,
            pending: true,
            whole,
            fixed_whole: false,
            stale: false,
            ..self.sweep.links[l]
        };
        self.sweep.dirty.push(link);
        self.sweep.pending.push(link);
        if whole || end > start {
            self.sweep.heap.push(Reverse(old << 1 | PASS));
        }
    }

    /// Flow `slot` is drawn into this sweep unfixed: the links it crosses count it so, and
    /// the dirty ones that have not fixed their flows must be evaluated again.
    fn draw_route(&mut self, slot: u32) {
        for &l in &self.flows[slot as usize].route {
            if !self.sweep.lone(l) {
                self.sweep.count_drawn(l, 1);
            }
        }
    }

    fn evaluate_pending(&mut self) {
        while let Some(link) = self.sweep.pending.pop() {
            self.sweep.links[link as usize].pending = false;
            self.evaluate(link);
        }
    }

    /// Whether `slot` is fixed when the sweep stands at `at`: settled in this sweep, or
    /// untouched with an old key below `at`.
    fn fixed_rate(&self, slot: u32, at: Key) -> Option<u64> {
        if let Some(sf) = self.swept_state(slot) {
            return sf.settled.then_some(sf.rate);
        }
        let key = self.old_key(slot);
        (key < at).then_some(self.keys.rate_at(key))
    }

    /// Finds where dirty `link` pops as things stand at `now`: its share from the flows fixed
    /// so far, raised as the untouched flows on it reach their old keys. Anything that later
    /// changes a flow on it evaluates it again, so the pop it records is exact when reached.
    fn evaluate(&mut self, link: LinkId) {
        #[cfg(any(test, feature = "counters"))]
        {
            self.evaluations.0 += 1;
            self.evaluations.1 += self.links[link as usize].flows.len() as u64;
            self.evaluations.2 += self.group_entries[link as usize].len() as u64;
        }
        let pop = self.pop_by_groups(link);
        #[cfg(test)]
        assert_eq!(pop, self.pop_by_flows(link), "link {link}: by groups");
        let sl = &mut self.sweep.links[link as usize];
        sl.stale = false;
        debug_assert!(
            pop >= self.sweep.now,
            "link {link}'s pop fell below the sweep"
        );
        self.sweep.links[link as usize].pop = pop;
        if pop != NONE {
            self.sweep.heap.push(Reverse(pop << 1 | POP));
        }
    }

    /// Where `link` pops, counted from the groups crossing it: the flows drawn into the sweep
    /// as the link's tallies have them, every other flow at its group's old key and rate.
    /// A group's members are drawn in exactly when its link is dirty, whenever a link is
    /// evaluated or popped: turning dirty draws them in (`mark_dirty`), and a member drawn in
    /// alone, fixed by another link at a key other than its old one (`fix`), has `settle`
    /// note its old bottleneck, which turns dirty there and then. The tests hold every
    /// evaluation to [`MaxMin::pop_by_flows`].
    fn pop_by_groups(&mut self, link: LinkId) -> Key {
        let now = self.sweep.now;
        let (drawn_unfixed, drawn_load) = self.sweep.drawn_on(link);
        let (mut unfixed, mut fixed_load) = (drawn_unfixed as u64, drawn_load as u128);
        let mut ahead = std::mem::take(&mut self.sweep.ahead);
        ahead.clear();
        let (mut ahead_flows, mut ahead_rates, mut ahead_share) = (0u64, 0u64, 0u64);
        for e in &self.group_entries[link as usize] {
            if self.sweep.is_dirty(e.group) {
                continue; // its members are drawn in and tallied
            }
            let old = self.last_key(e.group);
            let rate = self.keys.share_of(old).max(1);
            let n = e.crossing as u64;
            if old < now {
                fixed_load += rate as u128 * n as u128;
            } else {
                unfixed += n;
                ahead_flows += n;
                ahead_rates += rate * n;
                ahead_share = ahead_share.max(self.keys.share_of(old));
                ahead.push((old, rate, n));
            }
        }
        let left = (self.capacity.of(link) as u128).saturating_sub(fixed_load) as u64;
        let totals = (ahead_flows, ahead_rates, ahead_share);
        let pop = pop_from(self.keys, left, unfixed, link, &mut ahead, totals);
        self.sweep.ahead = ahead;
        pop
    }

    /// Where `link` pops, counted flow by flow: the tests' oracle for
    /// [`MaxMin::pop_by_groups`].
    #[cfg(test)]
    fn pop_by_flows(&mut self, link: LinkId) -> Key {
        let now = self.sweep.now;
        let mut ahead = std::mem::take(&mut self.sweep.ahead);
        ahead.clear();
        let mut left = self.capacity.of(link);
        let mut unfixed = 0u64;
        let (mut ahead_rates, mut ahead_share) = (0u64, 0u64);
        for &slot in &self.links[link as usize].flows {
            if let Some(sf) = self.swept_state(slot) {
                if sf.settled {
                    left = left.saturating_sub(sf.rate);
                } else {
                    unfixed += 1;
                }
                continue;
            }
            let (key, rate) = (self.old_key(slot), self.old_rate(slot));
            if key < now {
                left = left.saturating_sub(rate);
            } else {
                unfixed += 1;
                ahead_rates += rate;
                ahead_share = ahead_share.max(self.keys.share_of(key));
                ahead.push((key, rate, 1));
            }
        }
        let totals = (ahead.len() as u64, ahead_rates, ahead_share);
        let pop = pop_from(self.keys, left, unfixed, link, &mut ahead, totals);
        self.sweep.ahead = ahead;
        pop
    }

    /// Dirty `link` fixes every flow still unfixed on it at its key `at`. If every flow it
    /// fixed last time is still unfixed, they are fixed again together, as a group: no
    /// member is visited.
    fn pop(&mut self, link: LinkId, at: Key) {
        self.sweep.now = at;
        self.sweep.links[link as usize].popped = true;
        let rate = self.keys.share_of(at).max(1);
        let whole = self.group_unfixed(link);
        #[cfg(test)]
        {
            let epoch = self.sweep.epoch;
            let members = &self.groups[link as usize].slots;
            let (part, alone): (Vec<u32>, Vec<u32>) = members
                .iter()
                .partition(|&&s| self.flows[s as usize].swept_epoch != epoch);
            assert_eq!(whole, self.sweep.drawn_whole(link) && !part.is_empty());
            if whole {
                assert!(part.iter().all(|&s| self.fixed_rate(s, at).is_none()));
                assert!(alone.iter().all(|&s| self.fixed_rate(s, at).is_some()));
            }
        }
        if whole && self.fixes_its_group_alone(link, at) {
            #[cfg(test)]
            {
                self.popped_as.0 += 1;
                let flows = &self.links[link as usize].flows;
                let unfixed = flows.iter().filter(|&&s| self.fixed_rate(s, at).is_none());
                assert_eq!(unfixed.count(), self.in_group_state(link));
            }
            self.settle_group(link, rate, at);
            return;
        }
        #[cfg(test)]
        {
            self.popped_as.1 += 1;
        }
        let mut candidates = std::mem::take(&mut self.sweep.candidates);
        candidates.clear();
        self.maybe_unfixed_on(link, at, whole, &mut candidates);
        for &slot in &candidates {
            if self.fixed_rate(slot, at).is_some() {
                continue;
            }
            if whole && self.flows[slot as usize].group == link {
                continue; // fixed with its group below
            }
            self.settle(slot, rate, at);
        }
        self.sweep.candidates = candidates;
        if whole {
            self.settle_group(link, rate, at);
        }
    }

    /// Onto `out`, every flow on `link`, popping at `at`, that may be unfixed (and perhaps
    /// some that are not), leaving out its own group when `whole` (fixed as one): its flows,
    /// or, when fewer, the members crossing it of the groups not known to be fixed already (a
    /// dirty link that popped fixed all its members; an untouched one fixed them at its old
    /// key) and the flows added since the last solve, the only ones with no group.
    fn maybe_unfixed_on(&mut self, link: LinkId, at: Key, whole: bool, out: &mut Vec<u32>) {
        let flows = &self.links[link as usize].flows;
        let open = |g: LinkId| match (g == link, self.sweep.is_dirty(g)) {
            (true, _) => !whole,
            (false, true) => !self.sweep.links[g as usize].popped,
            (false, false) => self.sweep.links[g as usize].key >= at,
        };
        let entries = &self.group_entries[link as usize];
        let mut by_groups = self.added.len();
        for e in entries.iter().filter(|e| open(e.group)) {
            by_groups += self.groups[e.group as usize].slots.len();
            if by_groups >= flows.len() {
                out.extend_from_slice(flows);
                return;
            }
        }
        #[cfg(test)]
        {
            self.walked_by_groups += 1;
        }
        let crosses = |slot: u32| self.flows[slot as usize].route.contains(&link);
        for e in entries.iter().filter(|e| open(e.group)) {
            let members = &self.groups[e.group as usize].slots;
            out.extend(members.iter().filter(|&&s| e.group == link || crosses(s)));
        }
        let added = self
            .added
            .iter()
            .filter(|&&s| self.flows[s as usize].live && crosses(s));
        out.extend(added);
    }

    /// Whether dirty `link`'s group was drawn in whole and some of it is still in the group's
    /// state: those members are all unfixed (a member leaves the group's state only when some
    /// link fixes it alone), and `link` fixes them again together. A group not drawn in whole
    /// had a member fixed alone before it turned dirty; its members are settled one by one.
    fn group_unfixed(&self, link: LinkId) -> bool {
        self.sweep.drawn_whole(link)
            && (self.sweep.drawn_alone(link) as usize) < self.groups[link as usize].slots.len()
    }

    /// How many of `link`'s group are in the group's state (not drawn in alone).
    fn in_group_state(&self, link: LinkId) -> usize {
        self.groups[link as usize].slots.len() - self.sweep.drawn_alone(link) as usize
    }

    /// Whether, with `link`'s group (those of it in the group's state) unfixed at `at`, they
    /// are the only flows unfixed on it: no other flow drawn into the sweep is, and every other
    /// group crossing it either is drawn in (its link is dirty) or was fixed below `at`. Read
    /// from the link's tallies and its groups, without walking its flows.
    fn fixes_its_group_alone(&self, link: LinkId, at: Key) -> bool {
        let (drawn_unfixed, _) = self.sweep.drawn_on(link);
        drawn_unfixed as usize == self.in_group_state(link)
            && self.group_entries[link as usize].iter().all(|e| {
                e.group == link || self.sweep.is_dirty(e.group) || self.last_key(e.group) < at
            })
    }

    /// Flow `slot` is fixed at `rate` by the link of key `at`, as far as the flow is
    /// concerned; returns its rate and key before, and whether it was drawn in before.
    fn fix(&mut self, slot: u32, rate: u64, at: Key) -> (u64, Key, bool) {
        let epoch = self.sweep.epoch;
        let (old_rate, old_key, drawn) = match self.swept_state(slot) {
            Some(sf) => (sf.rate, sf.key, true),
            None => {
                #[cfg(any(test, feature = "counters"))]
                {
                    self.swept.0 += 1;
                    self.swept.1 += self.flows[slot as usize].route.len() as u64;
                }
                let key = self.old_key(slot);
                (self.keys.rate_at(key), key, false)
            }
        };
        let f = &self.flows[slot as usize];
        if f.swept_epoch != epoch && f.group != NO_GROUP {
            let g = f.group;
            self.sweep.link_seen(g).drawn_alone += 1;
        }
        self.flows[slot as usize].sweep_to(SweepFlow {
            epoch,
            settled: true,
            rate,
            key: at,
        });
        self.sweep.settled.push(slot);
        (old_rate, old_key, drawn)
    }

    /// `link`'s whole group, drawn in whole, fixed again by `link` at `rate` and key `at` as
    /// one (no member visited): what [`MaxMin::settle`] does to each member's links, done to
    /// each of the group's links once, with the count of members crossing it.
    fn settle_group(&mut self, link: LinkId, rate: u64, at: Key) {
        let old = self.last_key(link);
        let old_rate = self.keys.share_of(old).max(1);
        let delta = rate as i64 - old_rate as i64;
        let moved = old_rate != rate || old != at;
        #[cfg(test)]
        {
            self.settled_as.0 += 1;
        }
        debug_assert!(
            self.sweep.drawn_whole(link),
            "a group fixed whole was drawn in whole"
        );
        self.sweep.links[link as usize].fixed_whole = true;
        self.sweep.settled_groups.push(link);
        #[cfg(test)]
        {
            self.fixed_as_groups.0 += 1;
            self.fixed_as_groups.1 += (self.sweep.drawn_alone(link) > 0) as u64;
        }
        // Members fixed alone elsewhere settled their own links: the group's counts cross
        // them too, so their links are first given back what the counts will take.
        let alone = self.sweep.drawn_alone(link) > 0;
        if alone {
            self.for_links_of_drawn_alone(link, |sl| {
                sl.drawn_unfixed += 1;
                sl.delta -= delta;
            });
        }
        // Its links are read while their records change (noting a link reads only that
        // link's group, never this one: `link` is dirty already).
        let links = std::mem::take(&mut self.groups[link as usize].links);
        for &GroupLink {
            link: l, crossing, ..
        } in &links
        {
            let load = rate * crossing as u64;
            self.count_fixed(l, delta * crossing as i64, crossing, load, moved);
        }
        self.groups[link as usize].links = links;
        if alone {
            self.for_links_of_drawn_alone(link, |sl| sl.drawn_load -= rate);
        }
    }

    /// Applies `f` to each link a member of `link`'s group drawn in alone crosses, once per
    /// such member crossing it.
    fn for_links_of_drawn_alone(&mut self, link: LinkId, f: impl Fn(&mut SweepLink)) {
        let epoch = self.sweep.epoch;
        for &slot in &self.groups[link as usize].slots {
            let flow = &self.flows[slot as usize];
            if flow.swept_epoch != epoch {
                continue;
            }
            for &l in &flow.route {
                if !self.sweep.lone(l) {
                    f(self.sweep.link_seen(l));
                }
            }
        }
    }

    /// Flow `slot` is fixed at `rate` by the link of key `at`. Links that counted it
    /// differently last time turn dirty.
    fn settle(&mut self, slot: u32, rate: u64, at: Key) {
        let (old_rate, old_key, drawn) = self.fix(slot, rate, at);
        #[cfg(test)]
        {
            self.settled_as.1 += 1;
        }
        let delta = rate as i64 - old_rate as i64;
        // An added flow's links were all noted when the sweep began.
        let moved = old_key != NONE && (old_rate != rate || old_key != at);
        // Its route is read while its links' records change (a link it makes dirty draws in
        // only flows not yet fixed in this sweep, never this one).
        let route = std::mem::take(&mut self.flows[slot as usize].route);
        for &l in &route {
            self.count_fixed(l, delta, drawn as u32, rate, moved);
        }
        self.flows[slot as usize].route = route;
    }

    /// Flows crossing `link` were fixed in this sweep: they add `delta` to its load change and
    /// `load` to its drawn flows' load, and `fixed` of them were counted unfixed there. A
    /// dirty link that has not fixed its flows is evaluated again; if they `moved` (a rate or
    /// key other than last time), any other link is noted, in the same visit.
    #[inline]
    fn count_fixed(&mut self, link: LinkId, delta: i64, fixed: u32, load: u64, moved: bool) {
        if self.sweep.lone(link) {
            return;
        }
        let epoch = self.sweep.epoch;
        let sl = self.sweep.link_seen(link);
        sl.delta += delta;
        sl.drawn_unfixed -= fixed;
        sl.drawn_load += load;
        if sl.epoch == epoch {
            sl.stale |= !sl.popped && !sl.pending;
        } else if moved {
            if sl.key != NONE {
                self.mark_dirty(link);
            } else if !sl.suspect {
                sl.suspect = true;
                self.sweep.suspects.push(link);
            }
        }
    }

    /// The sweep passes dirty `link`'s old key: every flow it fixed last time that nothing
    /// has fixed yet was counted as fixed from here on by the links it crosses, which must
    /// be evaluated.
    fn pass_old_key(&mut self, link: LinkId, at: Key) {
        self.sweep.now = self.sweep.now.max(at);
        let epoch = self.sweep.epoch;
        if !self.sweep.drawn_whole(link) {
            // Drawn in flow by flow: a member was fixed alone before, so the group is never
            // still whole here; the run holds the rest.
            let (start, end) = self.sweep.unsettled_of[link as usize];
            for i in start..end {
                let slot = self.sweep.unsettled[i as usize];
                if !self.flows[slot as usize].settled {
                    self.note_route(slot);
                }
            }
            return;
        }
        if self.sweep.links[link as usize].fixed_whole {
            return;
        }
        if self.sweep.drawn_alone(link) == 0 {
            // Still whole and unfixed: its links once each (noting them reads only their
            // own groups: `link` is dirty already).
            let links = std::mem::take(&mut self.groups[link as usize].links);
            for gl in &links {
                self.note(gl.link);
            }
            self.groups[link as usize].links = links;
            return;
        }
        // The members still in the group's state are its unfixed ones.
        for i in 0..self.groups[link as usize].slots.len() {
            let slot = self.groups[link as usize].slots[i];
            if self.flows[slot as usize].swept_epoch != epoch {
                self.note_route(slot);
            }
        }
    }

    /// Notes every link flow `slot` crosses.
    fn note_route(&mut self, slot: u32) {
        for j in 0..self.flows[slot as usize].route.len() {
            let l = self.flows[slot as usize].route[j];
            self.note(l);
        }
    }

    /// Makes this sweep's rates the last solve's: what changed is listed while the old keys
    /// still give the old rates, then the dirty links take their new keys. A group fixed again
    /// whole keeps its members, so its new key is every member's new rate.
    fn commit(&mut self, changes: &mut Changes) {
        for i in 0..self.sweep.settled.len() {
            let slot = self.sweep.settled[i];
            let sf = self.flows[slot as usize].swept();
            let old = self.flows[slot as usize].group;
            let regrouped = old != self.keys.link_of(sf.key);
            let old_rate = self.old_rate(slot);
            if old_rate != sf.rate || regrouped {
                changes.flows.push((slot, old_rate));
            }
            if regrouped {
                if old != NO_GROUP {
                    self.leave(slot, old);
                }
                self.flows[slot as usize].group = self.keys.link_of(sf.key);
                self.join(slot, self.keys.link_of(sf.key));
            }
        }
        for &g in &self.sweep.settled_groups {
            let (old, new) = (self.last_key(g), self.sweep.links[g as usize].pop);
            if self.keys.rate_at(old) != self.keys.rate_at(new) {
                changes.groups.push((g, self.keys.rate_at(old)));
            }
        }
        let s = &mut self.sweep;
        for &l in &s.dirty {
            let sl = &mut s.links[l as usize];
            let link = &mut self.links[l as usize];
            sl.key = if sl.popped { sl.pop } else { NONE };
            if sl.seen == s.epoch && !sl.single {
                link.load = (link.load as i64 + sl.delta) as u64;
            }
        }
        for &l in &s.suspects {
            // A settled flow's links are all dirty, suspects or lone (keeping no load), so every
            // delta lands here (once: a link suspected for one added flow and made dirty for
            // another took its delta above).
            if s.links[l as usize].epoch == s.epoch || s.links[l as usize].single {
                continue;
            }
            let link = &mut self.links[l as usize];
            link.load = (link.load as i64 + s.links[l as usize].delta) as u64;
        }
    }
}

#[cfg(test)]
impl MaxMin {
    /// Whether every group holds exactly the flows its link fixed and counts their links.
    fn groups_add_up(&self) -> bool {
        let mut want: Vec<std::collections::BTreeMap<LinkId, u32>> =
            vec![Default::default(); self.links.len()];
        let mut members = vec![0u32; self.links.len()];
        for f in self.flows.iter().filter(|f| f.live && f.group != NO_GROUP) {
            let g = f.group as usize;
            members[g] += 1;
            for &l in &f.route {
                *want[g].entry(l).or_default() += 1;
            }
        }
        let entries_point_back = self.group_entries.iter().enumerate().all(|(l, es)| {
            es.iter().enumerate().all(|(e, entry)| {
                let gl = self.groups[entry.group as usize].links[entry.at as usize];
                gl.link == l as LinkId && gl.entry == e as u32
            })
        });
        entries_point_back
            && self.groups.iter().enumerate().all(|(g, group)| {
                let have: std::collections::BTreeMap<LinkId, u32> = group
                    .links
                    .iter()
                    .map(|gl| (gl.link, gl.crossing))
                    .collect();
                group.slots.len() == members[g] as usize
                    && group.slots.iter().enumerate().all(|(i, &slot)| {
                        let f = &self.flows[slot as usize];
                        f.live && f.group == g as LinkId && f.member_at == i as u32
                    })
                    && have == want[g]
                    && group.links.len() == have.len()
                    && group.links.iter().all(|gl| {
                        self.group_entries[gl.link as usize]
                            .iter()
                            .any(|e| e.group == g as LinkId && e.crossing == gl.crossing)
                    })
            })
    }

    /// Whether every link's load is the sum of its flows' rates.
    fn loads_add_up(&self) -> bool {
        (0..self.links.len() as LinkId).all(|l| {
            let flows = &self.links[l as usize].flows;
            let sum = flows.iter().map(|&s| self.old_rate(s)).sum::<u64>();
            self.load(l) == sum
                && (flows.len() > 1 || self.links[l as usize].load == 0)
                && self.sweep.links[l as usize].single == (flows.len() == 1)
        })
    }

    /// What [`MaxMin::solve`] must do, done plainly: every rate from [`reference_rates`],
    /// kept flow by flow (an instance solved this way is never solved incrementally).
    pub fn solve_from_scratch(&mut self, changed: &mut Vec<(u32, u64)>) {
        self.added.clear();
        self.shrunk.clear();
        let live: Vec<u32> = (0..self.flows.len() as u32)
            .filter(|&s| self.flows[s as usize].live)
            .collect();
        let routes: Vec<Vec<LinkId>> = live
            .iter()
            .map(|&s| self.flows[s as usize].route.clone())
            .collect();
        let rates = reference_rates(&self.capacity, self.links.len(), &routes);
        let kept = self.scratch_rates.get_or_insert_with(Vec::new);
        kept.resize(self.flows.len(), 0);
        for (&slot, rate) in live.iter().zip(rates) {
            let old = std::mem::replace(&mut kept[slot as usize], rate);
            if old != rate {
                changed.push((slot, old));
            }
        }
    }
}

/// Where a link with `left` capacity and `unfixed` flows pops, `ahead` of them still to be
/// fixed elsewhere (`totals`: how many, their rates' sum and the largest share among them):
/// by [`passes_all_ahead`]'s certificate if it holds, else by [`walk_to_pop`].
fn pop_from(
    keys: Keys,
    left: u64,
    unfixed: u64,
    link: LinkId,
    ahead: &mut [Ahead],
    (flows, rates, share): (u64, u64, u64),
) -> Key {
    match passes_all_ahead(left, unfixed, flows, rates, share) {
        Some(share) => share.map_or(NONE, |share| keys.key(share, link)),
        None => walk_to_pop(keys, left, unfixed, link, ahead).0,
    }
}

/// Where a link pops with `left` capacity and `unfixed` flows, of which those in `ahead` are
/// still to be fixed elsewhere, `count` at each (key, rate), in key order: the first share,
/// as they are, that does not lie above the next one's key (`NONE` if none is left unfixed);
/// and how many of the flows ahead were fixed before it. Sorts `ahead`.
fn walk_to_pop(
    keys: Keys,
    mut left: u64,
    mut unfixed: u64,
    link: LinkId,
    ahead: &mut [Ahead],
) -> (Key, u64) {
    ahead.sort_unstable();
    // The flows ahead one by one: `taken` of entry `next`'s count are passed.
    let (mut passed, mut next, mut taken) = (0, 0, 0);
    while unfixed > 0 {
        let candidate = keys.key(left / unfixed, link);
        match ahead.get(next) {
            Some(&(k, rate, count)) if k < candidate => {
                left = left.saturating_sub(rate);
                unfixed -= 1;
                passed += 1;
                taken += 1;
                if taken == count {
                    (next, taken) = (next + 1, 0);
                }
            }
            _ => return (candidate, passed),
        }
    }
    (NONE, passed)
}

/// [`walk_to_pop`] without the sort, when a certificate shows the link's share stays above
/// every one of the `ahead` flows' keys (summing to `rates`, the largest share `share`): with
/// room, once they are all fixed, of the `unfixed - ahead` other flows' `share + 1` each plus
/// one per flow ahead, every share on the walk exceeds the next key's share. Then the link
/// pops at its share after them all, or not at all if no other flow is left (`Some(None)`);
/// `None` if the certificate does not hold.
fn passes_all_ahead(
    left: u64,
    unfixed: u64,
    ahead: u64,
    rates: u64,
    share: u64,
) -> Option<Option<u64>> {
    let others = unfixed - ahead;
    let room = left.checked_sub(rates)?;
    if room < others.saturating_mul(share + 1).saturating_add(ahead) {
        return None;
    }
    Some((others > 0).then(|| room / others))
}

/// Whether `link`'s share, as the flows in `ahead` (key, rate) are fixed elsewhere in key
/// order and `extra` more stay unfixed throughout, always stays above the key of the next one
/// to be fixed (so it never is the smallest link while they are). Sorts `ahead`.
fn share_stays_above(
    keys: Keys,
    capacity: u64,
    link: LinkId,
    ahead: &mut [Ahead],
    extra: u64,
) -> bool {
    let all: u64 = ahead.iter().map(|a| a.2).sum();
    walk_to_pop(keys, capacity, all + extra, link, ahead).1 == all
}

#[cfg(test)]
/// Progressive filling from scratch over every link: the plain procedure [`MaxMin`] must
/// agree with. `routes[i]` is flow i's route; returns its rate.
pub fn reference_rates(capacity: &Capacities, links: usize, routes: &[Vec<LinkId>]) -> Vec<u64> {
    let mut on_link: Vec<Vec<usize>> = vec![Vec::new(); links];
    for (i, route) in routes.iter().enumerate() {
        for &l in route {
            on_link[l as usize].push(i);
        }
    }
    let mut left: Vec<u64> = (0..links as LinkId).map(|l| capacity.of(l)).collect();
    let mut unfixed: Vec<u64> = on_link.iter().map(|f| f.len() as u64).collect();
    let mut rate: Vec<Option<u64>> = vec![None; routes.len()];
    while let Some((share, l)) = (0..links)
        .filter(|&l| unfixed[l] > 0)
        .map(|l| (left[l] / unfixed[l], l))
        .min()
    {
        for &i in &on_link[l] {
            if rate[i].is_some() {
                continue;
            }
            let r = share.max(1);
            rate[i] = Some(r);
            for &l2 in &routes[i] {
                left[l2 as usize] = left[l2 as usize].saturating_sub(r);
                unfixed[l2 as usize] -= 1;
            }
        }
    }
    rate.into_iter()
        .map(|r| r.expect("every flow fixed"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// One step of a pattern: flows added (routes) and flows removed (indices into the live
    /// list, taken modulo its length), then a solve.
    #[derive(Clone, Debug)]
    struct Step {
        add: Vec<Vec<LinkId>>,
        remove: Vec<usize>,
    }

    fn route(links: u32) -> impl Strategy<Value = Vec<LinkId>> {
        // A path on a ring of links (what e-cube and ring routes look like), sometimes a
        // scattered set (a torus route crosses two dimensions).
        prop_oneof![
            (0..links, 1..6u32)
                .prop_map(move |(first, len)| (first..first + len).map(|l| l % links).collect()),
            proptest::collection::btree_set(0..links, 1..5).prop_map(|s| s.into_iter().collect()),
        ]
    }

    fn steps(links: u32) -> impl Strategy<Value = Vec<Step>> {
        let step = (
            proptest::collection::vec(route(links), 0..6),
            proptest::collection::vec(any::<usize>(), 0..4),
        )
            .prop_map(|(add, remove)| Step { add, remove });
        proptest::collection::vec(step, 1..40)
    }

    /// Applies `steps` to a `MaxMin` and checks every flow's rate against the reference
    /// after every solve, and that `changed` lists exactly the flows whose rate or
    /// bottleneck moved.
    fn check(capacity: u64, links: u32, steps: &[Step]) -> Result<(), TestCaseError> {
        check_counting(Capacities::Uniform(capacity), links, steps).map(|_| ())
    }

    /// [`check`], returning the solver with its counts of the ways it took.
    fn check_counting(
        capacity: Capacities,
        links: u32,
        steps: &[Step],
    ) -> Result<MaxMin, TestCaseError> {
        let mut mm = MaxMin::new(capacity.clone(), links as usize);
        let mut live: Vec<(u32, Vec<LinkId>)> = Vec::new();
        let mut free: Vec<u32> = Vec::new();
        let mut next = 0u32;
        let mut before: Vec<u64> = Vec::new();
        // Each flow's bottleneck after the last solve (`NO_LINK` before its first).
        const NO_LINK: LinkId = LinkId::MAX;
        let mut before_link: Vec<LinkId> = Vec::new();
        for step in steps {
            for &r in &step.remove {
                if live.is_empty() {
                    break;
                }
                let (slot, _) = live.swap_remove(r % live.len());
                mm.remove(slot);
                free.push(slot);
                before[slot as usize] = 0;
                before_link[slot as usize] = NO_LINK;
            }
            for route in &step.add {
                let slot = free.pop().unwrap_or_else(|| {
                    next += 1;
                    next - 1
                });
                mm.add(slot, route);
                live.push((slot, route.clone()));
            }
            let mut changes = Changes::default();
            mm.solve(&mut changes);
            let changed = mm.flow_by_flow(&changes);
            let mut once: Vec<u32> = changed.iter().map(|c| c.0).collect();
            once.sort_unstable();
            once.dedup();
            prop_assert_eq!(once.len(), changed.len(), "a flow listed twice");
            for &(g, _) in &changes.groups {
                prop_assert!(
                    mm.sweep.links[g as usize].fixed_whole,
                    "group {} fixed whole",
                    g
                );
            }
            let routes: Vec<Vec<LinkId>> = live.iter().map(|(_, r)| r.clone()).collect();
            let expected = reference_rates(&capacity, links as usize, &routes);
            before.resize(next as usize, 0);
            for ((slot, _), want) in live.iter().zip(&expected) {
                prop_assert_eq!(mm.rate(*slot), *want, "flow in slot {}", slot);
            }
            prop_assert!(mm.loads_add_up());
            prop_assert!(mm.groups_add_up());
            before_link.resize(next as usize, NO_LINK);
            let mut moved: Vec<u32> = live
                .iter()
                .filter(|(slot, _)| {
                    let s = *slot as usize;
                    before[s] != mm.rate(*slot) || before_link[s] != mm.bottleneck(*slot)
                })
                .map(|(slot, _)| *slot)
                .collect();
            let mut listed: Vec<u32> = changed.iter().map(|c| c.0).collect();
            moved.sort_unstable();
            listed.sort_unstable();
            prop_assert_eq!(listed, moved);
            for &(slot, old) in &changed {
                prop_assert_eq!(old, before[slot as usize]);
            }
            for (slot, _) in &live {
                before[*slot as usize] = mm.rate(*slot);
                before_link[*slot as usize] = mm.bottleneck(*slot);
                // One rate per group.
                prop_assert_eq!(Some(mm.rate(*slot)), mm.group_rate(mm.bottleneck(*slot)));
            }
        }
        Ok(mm)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3000))]

        /// Small capacities make floors, ties and shares of 0 (rate 1) common.
        #[test]
        fn equals_progressive_filling_from_scratch_small_capacity(
            capacity in 1u64..40, s in steps(10)
        ) {
            check(capacity, 10, &s)?;
        }

        #[test]
        fn equals_progressive_filling_from_scratch_real_capacity(s in steps(24)) {
            check(136_000_000, 24, &s)?;
        }

        /// One change per solve, as messages mostly start and end: adds and removals each
        /// meet their no-sweep tests and fall back to the sweep.
        #[test]
        fn equals_progressive_filling_one_change_at_a_time(
            capacity in prop_oneof![1u64..40, Just(1_000_003u64)],
            s in proptest::collection::vec(
                prop_oneof![
                    route(10).prop_map(|r| Step { add: vec![r], remove: vec![] }),
                    any::<usize>().prop_map(|i| Step { add: vec![], remove: vec![i] }),
                ],
                1..60,
            )
        ) {
            check(capacity, 10, &s)?;
        }

        /// Links of different capacities (a node's fast switch beside slower network links):
        /// small ones for ties and floors, and two rates ten apart.
        #[test]
        fn equals_progressive_filling_with_a_capacity_per_link(
            small in proptest::collection::vec(1u64..40, 10),
            two_rates in proptest::collection::vec(prop_oneof![Just(17_000_000u64), Just(170_000_000u64)], 10),
            use_small in any::<bool>(),
            s in steps(10)
        ) {
            let capacity = Capacities::PerLink(if use_small { small } else { two_rates });
            check_counting(capacity, 10, &s)?;
        }

        /// Links as fast as a key can hold on 24 links (the share takes every bit the link's
        /// index leaves), one of them 2 below, so shares and keys reach the top of their word.
        #[test]
        fn equals_progressive_filling_at_the_fastest_link_the_keys_hold(s in steps(24)) {
            let fastest = Keys::for_links(24, u64::MAX).unwrap_err();
            let mut capacity = vec![fastest; 24];
            capacity[3] = fastest - 2;
            check_counting(Capacities::PerLink(capacity), 24, &s)?;
        }
    }

    #[test]
    fn keys_hold_links_up_to_the_bits_their_index_leaves() {
        // 8 links take 3 bits, leaving 60 for the share below the heap's bit.
        assert_eq!(
            Keys::for_links(8, (1 << 60) - 1).map(|k| k.link_bits),
            Ok(3)
        );
        assert_eq!(
            Keys::for_links(8, 1 << 60).map(|k| k.link_bits),
            Err((1 << 60) - 1)
        );
        assert_eq!(
            Keys::for_links(9, 1 << 59).map(|k| k.link_bits),
            Err((1 << 59) - 1)
        );
        assert_eq!(
            Keys::for_links(1, (1 << 63) - 1).map(|k| k.link_bits),
            Ok(0)
        );
        assert_eq!(
            Keys::for_links(2048, 17_000_000 * 8).map(|k| k.link_bits),
            Ok(11)
        );
        let k = Keys::for_links(9, (1 << 59) - 1).unwrap();
        let top = k.key((1 << 59) - 1, 8);
        assert_eq!((k.share_of(top), k.link_of(top)), ((1 << 59) - 1, 8));
        assert!(
            top < 1 << 63,
            "a key leaves the heap's bit free (and so is below NONE)"
        );
    }

    /// A link that fixed nothing must fix a flow after a change elsewhere: its suspect check
    /// fails and the solve runs again with it in. Capacity 12; X carries a, b, c (share 4);
    /// W carries e and five more (share 2); Z carries a and e, 6 of 12 used, so it fixes
    /// nothing. When W's five others end, e could take 12 on W, but on Z only 12 - 4 = 8:
    /// Z now fixes e at 8.
    #[test]
    fn a_link_that_fixed_nothing_and_must_now_is_put_back() {
        let (x, w, z) = (0, 1, 2);
        let mut mm = MaxMin::new(Capacities::Uniform(12), 3);
        let routes: Vec<Vec<LinkId>> = vec![
            vec![x, z], // a
            vec![x],    // b
            vec![x],    // c
            vec![w, z], // e
            vec![w],
            vec![w],
            vec![w],
            vec![w],
            vec![w],
        ];
        for (slot, route) in routes.iter().enumerate() {
            mm.add(slot as u32, route);
        }
        let mut changed = Changes::default();
        mm.solve(&mut changed);
        assert_eq!(mm.rate(0), 4);
        assert_eq!(mm.rate(3), 2);
        assert_eq!(
            mm.sweep.links[z as usize].key, NONE,
            "Z fixes nothing at first"
        );
        for slot in 4..9 {
            mm.remove(slot);
        }
        let reruns = mm.sweeps.1;
        mm.solve(&mut changed);
        assert_eq!(mm.sweeps.1, reruns + 1, "Z's check failed once");
        assert_eq!(mm.rate(3), 8, "e is fixed by Z");
        assert_eq!(
            reference_rates(&Capacities::Uniform(12), 3, &routes[..4]),
            (0..4).map(|s| mm.rate(s)).collect::<Vec<_>>()
        );
        assert!(mm.loads_add_up());
        assert!(mm.groups_add_up());
    }

    /// A lone link (one flow crosses it, and it fixed nothing) is left out of the sweep, but
    /// not when its flow's rate reaches the capacity: `a` shares link 1 with `b`, which fixes
    /// both; when `b` leaves, `a` gets the whole capacity on both its links, and the filling
    /// fixes it at the lower index, link 0, the lone one. Its check fails once and the sweep
    /// runs again with link 0 in.
    #[test]
    fn a_lone_link_that_must_fix_its_flow_is_put_back() {
        // Flow a shares link 1 with b, which fixes it; when b ends, a runs alone at the
        // capacity and link 0, the lower of its two, must fix it. Found as the sweep begins,
        // one sweep does; left to the check after the sweep, it fails once and a second
        // sweep does. Both end with the same rates and groups.
        for marks_freed_fixers in [true, false] {
            let mut mm = MaxMin::new(Capacities::Uniform(10), 2);
            mm.marks_freed_fixers = marks_freed_fixers;
            mm.add(0, &[0, 1]); // a
            mm.add(1, &[1]); // b
            let mut changed = Changes::default();
            mm.solve(&mut changed);
            assert_eq!((mm.rate(0), mm.bottleneck(0)), (5, 1));
            assert_eq!(mm.sweep.links[0].key, NONE, "link 0 fixes nothing at first");
            mm.remove(1);
            let (sweeps, reruns) = mm.sweeps;
            mm.solve(&mut changed);
            let reruns_now = u64::from(!marks_freed_fixers);
            assert_eq!(
                mm.sweeps,
                (sweeps + 1, reruns + reruns_now),
                "link 0 found as the sweep begins: {marks_freed_fixers}"
            );
            assert_eq!(
                (mm.rate(0), mm.bottleneck(0)),
                (10, 0),
                "a is fixed by link 0"
            );
            assert!(mm.loads_add_up());
            assert!(mm.groups_add_up());
        }
    }

    #[test]
    fn equals_progressive_filling_on_a_long_random_pattern() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let links = 64u32;
        let route = |rng: &mut rand_chacha::ChaCha8Rng| -> Vec<LinkId> {
            let first = rng.gen_range(0..links);
            (first..first + rng.gen_range(1..9))
                .map(|l| l % links)
                .collect()
        };
        // 400 steps of several changes, then one change at a time (as messages mostly start
        // and end): 250 removals, draining the links, then 400 adds or removals.
        let mut steps: Vec<Step> = (0..400)
            .map(|_| Step {
                add: (0..rng.gen_range(0..8)).map(|_| route(&mut rng)).collect(),
                remove: (0..rng.gen_range(0..7)).map(|_| rng.gen()).collect(),
            })
            .collect();
        let one_change = |add: bool, rng: &mut rand_chacha::ChaCha8Rng| match add {
            true => Step {
                add: vec![route(rng)],
                remove: vec![],
            },
            false => Step {
                add: vec![],
                remove: vec![rng.gen()],
            },
        };
        steps.extend((0..250).map(|_| one_change(false, &mut rng)));
        steps.extend((0..400).map(|_| {
            let add = rng.gen_bool(0.5);
            one_change(add, &mut rng)
        }));
        let mm = check_counting(Capacities::Uniform(1_000_003), links, &steps).unwrap();
        let (whole, one_by_one) = mm.settled_as;
        let (alone, walked) = mm.popped_as;
        let (added, removed) = mm.alone;
        // Both ways of settling and of popping a link ran, and removals and adds that need no
        // sweep were taken, so the agreement covers each (every evaluation by groups is held
        // to one by flows as it happens).
        assert!(whole > 100, "groups fixed again whole: {whole}");
        let (as_one, in_part) = mm.fixed_as_groups;
        assert_eq!(as_one, whole, "each as one, no member visited");
        assert!(
            in_part > 10,
            "groups fixed as one after members left them: {in_part}"
        );
        assert!(one_by_one > 100, "flows settled one by one: {one_by_one}");
        assert!(alone > 100, "pops fixing their group alone: {alone}");
        assert!(walked > 100, "pops walking their flows: {walked}");
        let late = mm.evaluated_late;
        assert!(
            late > 10,
            "evaluations put off until a link's entry came up: {late}"
        );
        let by_groups = mm.walked_by_groups;
        assert!(
            by_groups > 10,
            "of them, walking the groups crossing them: {by_groups}"
        );
        assert!(removed > 10, "flows removed without a sweep: {removed}");
        assert!(added > 40, "flows added without a sweep: {added}");
    }
}
