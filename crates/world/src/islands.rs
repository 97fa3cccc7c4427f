//! Islands and sleep: groups of bodies at rest leave the solver, and their
//! contacts leave the narrowphase, until something touches them.
//!
//! ```text
//! islands persist:
//!   created dynamic body → its own island; a contact begins touching or a
//!   joint is created → the two islands merge (smaller into larger); a
//!   link goes away → the island counts it and may be split later
//! after each step (when sleep is enabled):
//!   timers   every awake dynamic body: slow (|v| and |ω|·reach below the
//!            threshold) → sleep_time += dt, else 0; keep-awake bodies
//!            (portal crossings) → 0
//!   split    the island of the sleepiest body, if it lost links, is split
//!            into its connected parts (one island per step, as Box2D);
//!            first from the ends of the contacts it lost (still whole,
//!            or one piece off), else over all its links
//!   sleep    an island whose every awake member rested long enough: its
//!            bodies leave the solver arrays (BodySet::sleep), its contacts
//!            move to the sleeping list (ContactSet::sleep_body)
//! wake (the whole island) when:
//!   an awake or kinematic body touches one of its bodies; a joint is
//!   created, destroyed or changed on one; any API call changes one
//!   (velocity, force, impulse, transform, mass, shapes)
//! ```
//!
//! | setting                    | unit | usual |
//! |----------------------------|------|-------|
//! | [`SleepSettings::linear_threshold`] | m/s  | 0.05  |
//! | [`SleepSettings::time_to_sleep`]    | s    | 0.5   |
//!
//! The stage owns the islands' membership, the bodies created asleep that
//! wait for the first step, and its scratch space; the world passes it the
//! bodies, shapes (for reach), contacts (and the links that began or ended
//! since it last looked) and joints.

use janus2d_core::body::{BodyHandle, BodySet, BodySim, BodyType};
use janus2d_core::math::Real;
use janus2d_core::parallel::Team;
use janus2d_core::union_find::{find, union};
use smallvec::SmallVec;

use crate::contacts::{ContactSet, TouchChanges};
use crate::error::WorldError;
use crate::joints::JointSet;
use crate::shapes::ShapeStore;

/// When bodies fall asleep.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SleepSettings {
    /// Sleep on (default, as Box2D and Rapier) or off.
    pub enabled: bool,
    /// Speed below which a body counts as at rest, m/s (usual 0.05); the
    /// angular part counts as `|ω|` times the body's reach.
    pub linear_threshold: Real,
    /// How long a whole island must rest before it sleeps, s (usual 0.5).
    pub time_to_sleep: Real,
}

impl Default for SleepSettings {
    fn default() -> Self {
        SleepSettings {
            enabled: true,
            linear_threshold: 0.05,
            time_to_sleep: 0.5,
        }
    }
}

impl SleepSettings {
    /// Checks the settings: both values finite and not negative; the error
    /// names the field.
    ///
    /// ```
    /// use janus2d_world::{SleepSettings, WorldError};
    /// let bad = SleepSettings { time_to_sleep: -1.0, ..SleepSettings::default() };
    /// assert_eq!(bad.validate(), Err(WorldError::OutOfRange("time_to_sleep")));
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        for (v, name) in [
            (self.linear_threshold, "linear_threshold"),
            (self.time_to_sleep, "time_to_sleep"),
        ] {
            if !v.is_finite() {
                return Err(WorldError::NonFinite(name));
            }
            if v < 0.0 {
                return Err(WorldError::OutOfRange(name));
            }
        }
        Ok(())
    }
}

/// No island (static and kinematic bodies, free slots).
const NONE: u32 = u32::MAX;

/// A group of dynamic bodies linked by touching contacts and joints.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Island {
    members: Vec<BodyHandle>,
    /// Links removed since the island was built or last split: it may
    /// have fallen apart.
    removed: u32,
    /// The two bodies of each ended contact counted in `removed`, while
    /// every removal so far was such a contact and there are at most
    /// [`MAX_CUTS`] of them (then `cuts.len() == removed`); otherwise the
    /// list falls short of the count, and a split looks at the whole
    /// island. Not in snapshots: a decoded island with removals is split
    /// in full.
    #[cfg_attr(feature = "serde", serde(skip))]
    cuts: Vec<[BodyHandle; 2]>,
    asleep: bool,
}

/// Most ended contacts an island remembers for the split's quick check
/// ([`Islands::quick_split`]); past it, the split looks at every link.
const MAX_CUTS: usize = 64;

/// What the split's quick check found ([`Islands::quick_split`]).
enum QuickSplit {
    /// Still one piece: the split would keep the island as it is.
    Whole,
    /// These bodies came off as one piece, and the rest is one piece.
    Piece(Vec<BodyHandle>),
    /// Not known: the whole split must look.
    Unknown,
}

/// How the quick check's two searches ended ([`Islands::search`]).
enum Search {
    /// They reached each other.
    Met,
    /// Front 0 or 1 ran out of bodies: all it reached is a piece.
    RanOut(usize),
    /// The visits' budget ran out first.
    OutOfBudget,
}

/// Persistent islands, bodies waiting to sleep, and scratch space.
///
/// ```text
/// create dynamic body      → island of its own
/// contact begins touching  → link: the smaller island joins the larger
/// joint created / enabled  → link
/// contact stops touching,  → removed += 1 (the island may have split)
/// joint removed / disabled,
/// body destroyed
/// sleepiest body's island  → split into its connected parts (one per step,
///   has removed > 0           union–find over its solid contacts and
///                             enabled joints; still whole → order kept);
///                             the quick check from the lost contacts'
///                             ends first (Islands::quick_split)
/// every member rested      → the island sleeps: bodies and contacts leave
///   time_to_sleep             the awake lists
/// ```
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct Islands {
    /// Island of each body slot.
    island_of: Vec<u32>,
    /// Position of each body slot in its island's member list.
    position: Vec<u32>,
    islands: Vec<Island>,
    free: Vec<u32>,
    /// Bodies created with `awake = false`, put to sleep at the next step.
    pending: Vec<BodyHandle>,
    /// Scratch of the sleep update (not state: not in snapshots): the
    /// least rested member's time by island, kept at MAX between steps.
    #[cfg_attr(feature = "serde", serde(skip))]
    min_time: Vec<Real>,
    /// Scratch: the islands whose `min_time` this step set.
    #[cfg_attr(feature = "serde", serde(skip))]
    touched: Vec<u32>,
    /// Scratch of a split: the union–find parent of each member position.
    #[cfg_attr(feature = "serde", serde(skip))]
    parent: Vec<u32>,
    /// Scratch of a split: the part of each root position.
    #[cfg_attr(feature = "serde", serde(skip))]
    part_of: Vec<u32>,
    /// Scratch of the quick check: the search that last reached each body
    /// slot (two stamps a search, one per end).
    #[cfg_attr(feature = "serde", serde(skip))]
    reached: Vec<u32>,
    /// Scratch of the quick check: the next search's first stamp.
    #[cfg_attr(feature = "serde", serde(skip))]
    stamp: u32,
    /// Scratch of the quick check: the two searches' queues.
    #[cfg_attr(feature = "serde", serde(skip))]
    fronts: [Vec<BodyHandle>; 2],
    /// Splits the quick check answered (for tests): whole, one piece off.
    #[cfg_attr(feature = "serde", serde(skip))]
    quick_splits: [u64; 2],
}

/// What the sleep update reads besides the bodies it changes.
pub(crate) struct SleepInput<'a> {
    pub(crate) dt: Real,
    pub(crate) settings: SleepSettings,
    pub(crate) shapes: &'a ShapeStore,
    /// Bodies that must not fall asleep this step (portal crossings).
    pub(crate) keep_awake: &'a [BodyHandle],
}

/// Bodies per block of the sleep timers on the team (below two blocks, the
/// caller runs them alone).
const TIMER_BLOCK: usize = 1024;

impl Islands {
    /// The id of the island `body` belongs to (read-only, for drawing);
    /// `None` for static and kinematic bodies. Ids are reused once an
    /// island is gone.
    pub(crate) fn island_id(&self, body: BodyHandle) -> Option<u32> {
        Some(self.island(body)).filter(|&id| id != NONE)
    }

    fn island(&self, body: BodyHandle) -> u32 {
        self.island_of
            .get(body.index as usize)
            .copied()
            .unwrap_or(NONE)
    }

    fn set_island(&mut self, body: BodyHandle, id: u32) {
        let i = body.index as usize;
        if self.island_of.len() <= i {
            self.island_of.resize(i + 1, NONE);
            self.position.resize(i + 1, 0);
        }
        self.island_of[i] = id;
    }

    /// Records that `body` is member `k` of island `id`.
    fn place(&mut self, body: BodyHandle, id: u32, k: usize) {
        self.set_island(body, id);
        self.position[body.index as usize] = k as u32;
    }

    fn new_island(&mut self, members: Vec<BodyHandle>) -> u32 {
        let island = Island {
            members,
            removed: 0,
            cuts: Vec::new(),
            asleep: false,
        };
        let id = match self.free.pop() {
            Some(id) => {
                self.islands[id as usize] = island;
                id
            }
            None => {
                self.islands.push(island);
                (self.islands.len() - 1) as u32
            }
        };
        for k in 0..self.islands[id as usize].members.len() {
            let m = self.islands[id as usize].members[k];
            self.place(m, id, k);
        }
        id
    }

    /// Checks the islands against the bodies (for `World::validate`):
    /// every live dynamic body in exactly one island at its recorded
    /// position, members live and dynamic, free ids empty, an island that
    /// sleeps has only sleeping members, pending bodies live.
    pub(crate) fn check(&self, bodies: &BodySet) -> Result<(), String> {
        if self.island_of.len() != self.position.len() {
            return Err(format!(
                "{} island ids, {} positions",
                self.island_of.len(),
                self.position.len()
            ));
        }
        // Every recorded place names a member (the members below name their
        // places back): no id or position out of range.
        for (i, (&id, &k)) in self.island_of.iter().zip(&self.position).enumerate() {
            if id == NONE {
                continue;
            }
            let member = self
                .islands
                .get(id as usize)
                .and_then(|island| island.members.get(k as usize));
            if member.map(|m| m.index as usize) != Some(i) {
                return Err(format!(
                    "body slot {i}: island {id} position {k} names another"
                ));
            }
        }
        let mut free_seen = vec![false; self.islands.len()];
        for &id in &self.free {
            match free_seen.get_mut(id as usize) {
                Some(seen) if !*seen => *seen = true,
                _ => return Err(format!("free island id {id} out of range or repeated")),
            }
        }
        // Scratch kept between steps: `min_time` all at MAX.
        if self.min_time.iter().any(|&t| t != Real::MAX) {
            return Err("island scratch times not reset".into());
        }
        let mut members = 0usize;
        for (id, island) in self.islands.iter().enumerate() {
            let free = free_seen[id];
            if free != island.members.is_empty() {
                return Err(format!(
                    "island {id}: free {free} with {} members",
                    island.members.len()
                ));
            }
            for (k, &m) in island.members.iter().enumerate() {
                members += 1;
                if bodies.body_type(m) != Some(BodyType::Dynamic) {
                    return Err(format!(
                        "island {id}: member {m:?} is not a live dynamic body"
                    ));
                }
                if self.island(m) != id as u32
                    || self.position.get(m.index as usize) != Some(&(k as u32))
                {
                    return Err(format!("island {id}: member {m:?} records another place"));
                }
                if island.asleep && !bodies.is_sleeping(m) {
                    return Err(format!("island {id} sleeps but member {m:?} is awake"));
                }
            }
        }
        let dynamic = bodies
            .handles()
            .filter(|&h| bodies.body_type(h) == Some(BodyType::Dynamic) && !bodies.is_disabled(h))
            .count();
        if dynamic != members {
            return Err(format!(
                "{dynamic} dynamic bodies, {members} island members"
            ));
        }
        if let Some(b) = self.pending.iter().find(|b| !bodies.contains(**b)) {
            return Err(format!("pending body {b:?} is not live"));
        }
        Ok(())
    }

    /// A new dynamic body: an island of its own.
    pub(crate) fn add_body(&mut self, body: BodyHandle) {
        self.new_island(vec![body]);
    }

    /// Forgets a body that is being destroyed (it must be awake).
    pub(crate) fn remove_body(&mut self, body: BodyHandle) {
        self.pending.retain(|b| *b != body);
        let id = self.island(body);
        if id == NONE {
            return;
        }
        let k = self.position[body.index as usize] as usize;
        self.set_island(body, NONE);
        let island = &mut self.islands[id as usize];
        island.members.swap_remove(k);
        island.removed = island.removed.saturating_add(1);
        if let Some(&moved) = island.members.get(k) {
            self.position[moved.index as usize] = k as u32;
        }
        let island = &self.islands[id as usize];
        if island.members.is_empty() {
            self.free.push(id);
        }
    }

    /// Two bodies became linked (touching contact, joint): their islands
    /// merge, the smaller into the larger.
    pub(crate) fn link(&mut self, a: BodyHandle, b: BodyHandle, bodies: &BodySet) {
        if !(bodies.contains(a) && bodies.contains(b)) {
            return;
        }
        let (ia, ib) = (self.island(a), self.island(b));
        if ia == NONE || ib == NONE || ia == ib {
            return;
        }
        let (big, small) =
            if self.islands[ia as usize].members.len() >= self.islands[ib as usize].members.len() {
                (ia, ib)
            } else {
                (ib, ia)
            };
        let moved = std::mem::take(&mut self.islands[small as usize]);
        let base = self.islands[big as usize].members.len();
        for (k, m) in moved.members.iter().enumerate() {
            self.place(*m, big, base + k);
        }
        let island = &mut self.islands[big as usize];
        island.members.extend(moved.members);
        island.removed = island.removed.saturating_add(moved.removed);
        if island.cuts.len() + moved.cuts.len() <= MAX_CUTS {
            island.cuts.extend(moved.cuts);
        } else {
            // Too many to check one by one: the next split looks at all.
            island.cuts.clear();
        }
        island.asleep = false;
        self.free.push(small);
    }

    /// A link of `body` went away: its island may split.
    pub(crate) fn note_removed(&mut self, body: BodyHandle) {
        let id = self.island(body);
        if id != NONE {
            self.islands[id as usize].removed = self.islands[id as usize].removed.saturating_add(1);
        }
    }

    /// Two bodies exchanged identities (portal handover): each handle keeps
    /// the island of the object it now names.
    pub(crate) fn swap_bodies(&mut self, a: BodyHandle, b: BodyHandle) {
        let (ia, ib) = (self.island(a), self.island(b));
        if ia == ib {
            // One island holds both: membership is unchanged.
            if ia != NONE {
                self.islands[ia as usize].removed =
                    self.islands[ia as usize].removed.saturating_add(1);
            }
            return;
        }
        for (id, from, to) in [(ia, a, b), (ib, b, a)] {
            if id != NONE {
                for m in &mut self.islands[id as usize].members {
                    if *m == from {
                        *m = to;
                    }
                }
            }
        }
        let (pa, pb) = (
            self.position.get(a.index as usize).copied().unwrap_or(0),
            self.position.get(b.index as usize).copied().unwrap_or(0),
        );
        self.place(a, ib, pb as usize);
        self.place(b, ia, pa as usize);
        for id in [ia, ib] {
            if id != NONE {
                self.islands[id as usize].removed =
                    self.islands[id as usize].removed.saturating_add(1);
            }
        }
    }

    /// A solid contact between `a` and `b` ended: as
    /// [`note_removed`](Self::note_removed) of `a`, and the island of `a`
    /// remembers the pair for the split's quick check.
    fn note_cut(&mut self, a: BodyHandle, b: BodyHandle) {
        let id = self.island(a);
        if id != NONE {
            let island = &mut self.islands[id as usize];
            island.removed = island.removed.saturating_add(1);
            if island.cuts.len() < MAX_CUTS {
                island.cuts.push([a, b]);
            }
        }
    }

    /// Takes the contacts that began and stopped touching during the step
    /// (handed over by the pipeline): links and possible splits.
    pub(crate) fn apply_touch_changes(&mut self, changes: TouchChanges, bodies: &BodySet) {
        for (a, b) in changes.began {
            self.link(a, b, bodies);
        }
        for (a, b) in changes.ended {
            self.note_cut(a, b);
        }
    }

    /// A body created asleep: it sleeps at the next step unless touched.
    pub(crate) fn push_pending(&mut self, body: BodyHandle) {
        self.pending.push(body);
    }

    /// Puts the bodies created asleep to sleep (when sleep is on).
    pub(crate) fn apply_pending(&mut self, enabled: bool, bodies: &mut BodySet) {
        if self.pending.is_empty() {
            return;
        }
        for b in std::mem::take(&mut self.pending) {
            if enabled {
                bodies.sleep(b);
            }
        }
    }

    /// Puts the island of awake dynamic `body` to sleep now (its bodies
    /// leave the solver, its contacts the narrowphase). A body without an
    /// island sleeps alone.
    pub(crate) fn sleep_now(
        &mut self,
        body: BodyHandle,
        bodies: &mut BodySet,
        contacts: &mut ContactSet,
    ) {
        let id = self.island(body);
        if id == NONE {
            bodies.sleep(body);
            contacts.sleep_body(body, bodies);
            return;
        }
        let island = &mut self.islands[id as usize];
        if island.asleep {
            return;
        }
        island.asleep = true;
        for m in &island.members {
            bodies.sleep(*m);
        }
        for m in &island.members {
            contacts.sleep_body(*m, bodies);
        }
    }

    /// Wakes the island of `body`: its bodies return to the solver and its
    /// contacts to the narrowphase. No effect on awake or static bodies.
    pub(crate) fn wake(
        &mut self,
        body: BodyHandle,
        bodies: &mut BodySet,
        contacts: &mut ContactSet,
    ) {
        if !self.pending.is_empty() {
            // A body created asleep that the user touched stays awake.
            self.pending.retain(|b| *b != body);
        }
        if !bodies.is_sleeping(body) {
            return;
        }
        let id = self.island(body);
        if id == NONE || !self.islands[id as usize].asleep {
            // Asleep on its own (created asleep).
            bodies.wake(body);
            contacts.wake_body(body);
            return;
        }
        let island = &mut self.islands[id as usize];
        island.asleep = false;
        for m in &island.members {
            bodies.wake(*m);
        }
        for m in &island.members {
            contacts.wake_body(*m);
        }
    }

    /// Updates sleep timers, splits the sleepiest island that may have
    /// fallen apart, and puts resting islands to sleep.
    pub(crate) fn update(
        &mut self,
        input: &SleepInput<'_>,
        bodies: &mut BodySet,
        contacts: &mut ContactSet,
        joints: &JointSet,
        team: &Team,
    ) {
        let settings = input.settings;
        let tol2 = settings.linear_threshold * settings.linear_threshold;
        let n = bodies.sims.len();
        if n <= 1 {
            return; // nothing awake
        }
        // Timers (slot 0 is the static sentinel), each body on its own:
        // in blocks on the team.
        let (sims, states) = (&mut bodies.sims[1..], &bodies.states[1..]);
        let timers = |first: usize, sims: &mut [BodySim]| {
            for (sim, st) in sims.iter_mut().zip(&states[first..]) {
                let tol2 = sim.sleep_threshold.map_or(tol2, |t| t * t);
                // The shapes' reach (random reads of the shape records)
                // only where the linear speed leaves the turn to decide.
                let turn_slow = || {
                    let reach = input.shapes.reach(sim.handle, sim.center);
                    st.w * st.w * reach * reach <= tol2
                };
                let slow = st.v.length_squared() <= tol2 && turn_slow();
                if sim.body_type == BodyType::Dynamic && slow && sim.enable_sleep {
                    sim.sleep_time += input.dt;
                } else {
                    sim.sleep_time = 0.0;
                }
            }
        };
        if team.threads() > 1 && sims.len() > TIMER_BLOCK {
            team.for_each_chunk_mut(sims, TIMER_BLOCK, |b, block| timers(b * TIMER_BLOCK, block));
        } else {
            timers(0, sims);
        }
        for &b in input.keep_awake {
            if let Some(i) = dynamic_index(bodies, b) {
                bodies.sims[i as usize].sleep_time = 0.0;
            }
        }
        // The sleepiest body whose island may have split: split that one.
        // (The body's own fields first: its island is a random read, and
        // in a scene in motion hardly any body is sleepy enough.)
        let mut candidate = (NONE, 0.0 as Real);
        let mut any_rested = false;
        for sim in &bodies.sims[1..n] {
            any_rested |= sim.sleep_time >= settings.time_to_sleep;
            let sleepiest = sim.sleep_time >= settings.time_to_sleep
                && sim.sleep_time > candidate.1
                && sim.body_type == BodyType::Dynamic;
            if !sleepiest {
                continue;
            }
            let id = self.island(sim.handle);
            if id != NONE && self.islands[id as usize].removed > 0 {
                candidate = (id, sim.sleep_time);
            }
        }
        if candidate.0 != NONE {
            let id = candidate.0;
            #[cfg(debug_assertions)]
            let before = self.clone();
            match self.quick_split(id, contacts, joints) {
                QuickSplit::Whole => {
                    // What the split would find: one part, the order kept.
                    self.quick_splits[0] += 1;
                    let island = &mut self.islands[id as usize];
                    island.removed = 0;
                    island.cuts.clear();
                }
                QuickSplit::Piece(piece) => {
                    self.quick_splits[1] += 1;
                    self.split_off(id, piece);
                }
                QuickSplit::Unknown => self.split(id, contacts, joints),
            }
            #[cfg(debug_assertions)]
            self.debug_check_split(&before, id, contacts, joints);
        }
        // An island sleeps when its least rested member has rested long
        // enough: with no awake body rested that long, none does (a scene
        // in motion skips the pass and its island lookups).
        if !any_rested {
            return;
        }
        // The least rested awake member of each island with awake members
        // (sleeping islands are not visited; `min_time` is kept at MAX
        // between steps, so only the touched entries are reset).
        let mut min_time = std::mem::take(&mut self.min_time);
        min_time.resize(self.islands.len(), Real::MAX);
        let mut touched = std::mem::take(&mut self.touched);
        touched.clear();
        for i in 1..n {
            let sim = &bodies.sims[i];
            let id = self.island(sim.handle);
            if id != NONE {
                let t = &mut min_time[id as usize];
                if *t == Real::MAX {
                    touched.push(id);
                }
                *t = t.min(sim.sleep_time);
            }
        }
        // In island order, as a pass over every island would visit them.
        touched.sort_unstable();
        for &id in &touched {
            let id = id as usize;
            let rested = min_time[id] >= settings.time_to_sleep;
            min_time[id] = Real::MAX;
            let island = &self.islands[id];
            if island.asleep || island.members.is_empty() || !rested {
                continue;
            }
            self.islands[id].asleep = true;
            let island = &self.islands[id];
            for m in &island.members {
                bodies.sleep(*m);
            }
            for m in &island.members {
                contacts.sleep_body(*m, bodies);
            }
        }
        self.min_time = min_time;
        self.touched = touched;
    }

    /// The split's quick check: what splitting island `id` would do, found
    /// from the ends of its ended contacts rather than from all its links.
    ///
    /// The island was connected when it was built or last split (merges
    /// join connected islands by a link), and since then every removal was
    /// an ended contact it remembers (`cuts.len() == removed`; anything
    /// else, such as a joint removed or a body destroyed, answers
    /// [`QuickSplit::Unknown`]). Each remembered contact whose two ends
    /// are members is looked at in turn: two searches grow from its ends
    /// over the members' solid contacts and enabled joints (the links the
    /// split reads), a node at a time from the smaller front, breadth
    /// first. They meet (still joined round the missing link), or one
    /// front runs out: all it reached is a piece of its own, kept aside.
    /// Contacts with an end in that piece are not searched; their other
    /// ends (the piece's old neighbours) must all reach each other. Then
    /// the rest is one piece: a path of old between two parts of it either
    /// goes round each missing link between its members, or through the
    /// piece, which it enters and leaves at those neighbours. A second
    /// piece, or the budget of visits (an eighth of the island) running
    /// out, answers `Unknown`, and the whole split finds the parts.
    fn quick_split(&mut self, id: u32, contacts: &ContactSet, joints: &JointSet) -> QuickSplit {
        let island = &self.islands[id as usize];
        if island.cuts.len() != island.removed as usize || island.members.is_empty() {
            return QuickSplit::Unknown;
        }
        let mut budget = island.members.len() / 8 + 16;
        if self.reached.len() < self.island_of.len() {
            self.reached.resize(self.island_of.len(), 0);
        }
        // Two stamps a search, at most one search a remembered end.
        let needed = 4 * MAX_CUTS as u32 + 2;
        if self.stamp == 0 || self.stamp >= u32::MAX - needed {
            // First use, or the stamps ran out: no body reached by any.
            self.reached.fill(0);
            self.stamp = 1;
        }
        let cuts = std::mem::take(&mut self.islands[id as usize].cuts);
        // The piece kept aside (its stamp and bodies), and its neighbours.
        let mut aside: Option<(u32, Vec<BodyHandle>)> = None;
        let mut outer: SmallVec<[BodyHandle; 4]> = SmallVec::new();
        let mut unknown = false;
        for &[a, b] in &cuts {
            if self.island(a) != id || self.island(b) != id {
                continue; // not a link between members: nothing to go round
            }
            // A contact with an end in the piece aside is not searched:
            // its other end is one of the piece's old neighbours.
            let inside = |x: BodyHandle| {
                aside
                    .as_ref()
                    .is_some_and(|(stamp, _)| self.reached[x.index as usize] == *stamp)
            };
            match (inside(a), inside(b)) {
                (true, true) => continue,
                (true, false) => {
                    outer.push(b);
                    continue;
                }
                (false, true) => {
                    outer.push(a);
                    continue;
                }
                (false, false) => {}
            }
            match self.search(id, [a, b], contacts, joints, &mut budget) {
                Search::Met => {}
                Search::RanOut(side) if aside.is_none() => {
                    aside = Some(self.take_front(side));
                    outer.push([a, b][1 - side]);
                }
                // A second piece, or the budget gone.
                _ => {
                    unknown = true;
                    break;
                }
            }
        }
        // The piece's old neighbours: all in one part of the rest.
        if !unknown && let Some((&first, others)) = outer.split_first() {
            for &other in others {
                if !matches!(
                    self.search(id, [first, other], contacts, joints, &mut budget),
                    Search::Met
                ) {
                    unknown = true;
                    break;
                }
            }
        }
        self.islands[id as usize].cuts = cuts;
        match aside {
            _ if unknown => QuickSplit::Unknown,
            Some((_, bodies)) => QuickSplit::Piece(bodies),
            None => QuickSplit::Whole,
        }
    }

    /// The stamp and bodies of front `side` of the last search (the front
    /// is taken; the next search starts an empty one).
    fn take_front(&mut self, side: usize) -> (u32, Vec<BodyHandle>) {
        (
            self.stamp - 2 + side as u32,
            std::mem::take(&mut self.fronts[side]),
        )
    }

    /// Applies [`QuickSplit::Piece`]: island `id` minus `piece` stays one
    /// island and `piece` becomes another, as [`split`](Self::split) makes
    /// them (members in island order, the part holding the first member
    /// keeps the id).
    fn split_off(&mut self, id: u32, mut piece: Vec<BodyHandle>) {
        let stamp = self.reached[piece[0].index as usize];
        let members = std::mem::take(&mut self.islands[id as usize].members);
        let position = &self.position;
        piece.sort_unstable_by_key(|m| position[m.index as usize]);
        let reached = &self.reached;
        let rest: Vec<BodyHandle> = members
            .iter()
            .copied()
            .filter(|m| reached[m.index as usize] != stamp)
            .collect();
        let (kept, new) = if reached[members[0].index as usize] == stamp {
            (piece, rest)
        } else {
            (rest, piece)
        };
        self.keep_part(id, kept);
        self.new_island(new);
    }

    /// Island `id` becomes the part `members` (placed in this order), with
    /// no removals left to look at.
    fn keep_part(&mut self, id: u32, members: Vec<BodyHandle>) {
        for (k, m) in members.iter().enumerate() {
            self.place(*m, id, k);
        }
        let island = &mut self.islands[id as usize];
        island.members = members;
        island.removed = 0;
        island.cuts.clear();
    }

    /// Debug builds: what the whole split makes of island `id` in `before`
    /// is what the quick one made here.
    #[cfg(debug_assertions)]
    fn debug_check_split(&self, before: &Self, id: u32, contacts: &ContactSet, joints: &JointSet) {
        let mut full = before.clone();
        full.split(id, contacts, joints);
        let state = |s: &Self| {
            let islands: Vec<_> = s
                .islands
                .iter()
                .map(|i| (i.members.clone(), i.removed, i.asleep))
                .collect();
            (
                islands,
                s.free.clone(),
                s.island_of.clone(),
                s.position.clone(),
            )
        };
        debug_assert!(
            state(&full) == state(self),
            "island {id}: the quick split differs from the whole split"
        );
    }

    /// Two searches over members of island `id`, from `ends[0]` and
    /// `ends[1]`, within `budget` node visits (taken from it); each marks
    /// the bodies it reaches with its own stamp and keeps them in its
    /// front.
    fn search(
        &mut self,
        id: u32,
        ends: [BodyHandle; 2],
        contacts: &ContactSet,
        joints: &JointSet,
        budget: &mut usize,
    ) -> Search {
        let stamps = [self.stamp, self.stamp + 1];
        self.stamp += 2;
        if ends[0] == ends[1] {
            return Search::Met;
        }
        let mut fronts = std::mem::take(&mut self.fronts);
        for (side, front) in fronts.iter_mut().enumerate() {
            front.clear();
            front.push(ends[side]);
            self.reached[ends[side].index as usize] = stamps[side];
        }
        let (island_of, reached) = (&self.island_of, &mut self.reached);
        // Breadth first: each front is a queue read from `heads`.
        let mut heads = [0usize; 2];
        let found = 'search: loop {
            // The smaller front grows by one node.
            let left = |s: usize| fronts[s].len() - heads[s];
            let side = usize::from(left(1) < left(0));
            let Some(&body) = fronts[side].get(heads[side]) else {
                break Search::RanOut(side);
            };
            heads[side] += 1;
            if *budget == 0 {
                break Search::OutOfBudget;
            }
            *budget -= 1;
            let joint_others = joints.of_body(body).iter().filter_map(|&j| {
                joints
                    .get(j)
                    .ok()
                    .filter(|joint| joint.is_enabled())
                    .and_then(|joint| joint.other_body(body))
            });
            for other in contacts.links_of(body).chain(joint_others) {
                let i = other.index as usize;
                if island_of.get(i) != Some(&id) {
                    continue;
                }
                if reached[i] == stamps[1 - side] {
                    break 'search Search::Met;
                }
                if reached[i] != stamps[side] {
                    reached[i] = stamps[side];
                    fronts[side].push(other);
                }
            }
        };
        self.fronts = fronts;
        found
    }

    /// Splits island `id` into its connected parts over the members' own
    /// touching solid contacts and enabled joints.
    ///
    /// Union–find over the members' positions (as Box2D's split), so a
    /// contact is read once, not once from each body. The links come from
    /// one pass over the contact set's compact link array when the island
    /// holds a fair share of the world, else from each member's own
    /// contacts (a small island in a large world); both give the same
    /// parts. Each part keeps its members in island order, and the part of
    /// the first member keeps the id. An island still in one piece keeps
    /// its member order.
    fn split(&mut self, id: u32, contacts: &ContactSet, joints: &JointSet) {
        let members = std::mem::take(&mut self.islands[id as usize].members);
        let n = members.len();
        let mut parent = std::mem::take(&mut self.parent);
        parent.clear();
        parent.extend(0..n as u32);
        let island_of = &self.island_of;
        let position = &self.position;
        // The member position of `b`, when it is a member of this island.
        let place = |b: BodyHandle| -> Option<u32> {
            let i = b.index as usize;
            (island_of.get(i) == Some(&id)).then(|| position[i])
        };
        let mut join = |a: BodyHandle, b: BodyHandle| {
            if let (Some(pa), Some(pb)) = (place(a), place(b)) {
                union(&mut parent, pa, pb);
            }
        };
        // A per-member walk reads a link at random per contact; the pass
        // reads every link in order, about this many times cheaper each.
        const SCAN_PER_WALK: usize = 32;
        if n.saturating_mul(SCAN_PER_WALK) >= contacts.link_slots() {
            contacts.for_each_solid_link(&mut join);
        } else {
            for &b in &members {
                for other in contacts.links_of(b) {
                    join(b, other);
                }
            }
        }
        for &b in &members {
            for &j in joints.of_body(b) {
                if let Ok(joint) = joints.get(j)
                    && joint.is_enabled()
                    && let Some(other) = joint.other_body(b)
                {
                    join(b, other);
                }
            }
        }
        // Parts in order of their first member.
        let mut part_of = std::mem::take(&mut self.part_of);
        part_of.clear();
        part_of.resize(n, NONE);
        let mut part_count = 0u32;
        for i in 0..n as u32 {
            let r = find(&mut parent, i);
            if part_of[r as usize] == NONE {
                part_of[r as usize] = part_count;
                part_count += 1;
            }
        }
        if part_count <= 1 {
            let island = &mut self.islands[id as usize];
            island.members = members;
            island.removed = 0;
            island.cuts.clear();
        } else {
            let mut parts: Vec<Vec<BodyHandle>> = vec![Vec::new(); part_count as usize];
            for (i, &m) in members.iter().enumerate() {
                let r = find(&mut parent, i as u32);
                parts[part_of[r as usize] as usize].push(m);
            }
            let mut parts = parts.into_iter();
            if let Some(first) = parts.next() {
                self.keep_part(id, first);
            }
            for part in parts {
                self.new_island(part);
            }
        }
        if self.islands[id as usize].members.is_empty() {
            self.free.push(id);
        }
        self.parent = parent;
        self.part_of = part_of;
    }
}

/// The state index of an awake dynamic body.
fn dynamic_index(bodies: &BodySet, b: BodyHandle) -> Option<u32> {
    let i = bodies.state_index(b)?;
    (i != 0 && bodies.sims[i as usize].body_type == BodyType::Dynamic).then_some(i)
}

#[cfg(test)]
mod tests {
    use janus2d_core::geometry::shapes::{Circle, Polygon};
    use janus2d_core::math::{Real, Vec2};

    use crate::{ShapeDef, World, WorldDef};
    use janus2d_core::body::BodyDef;

    const DT: Real = 1.0 / 60.0;

    /// A row of six touching boxes resting on the ground, and a ball with
    /// no friction sliding along their tops at 1 m/s: each time it leaves
    /// a box their contact ends, while the row and the slider are still
    /// one piece through its next box, until it slides off the row's end.
    /// The row rests long enough to make the island the split's candidate
    /// while the slider keeps it awake. The quick check must keep the
    /// island whole while the slider rides the row, and take the ball off
    /// as one piece once it has left (debug builds also run the whole
    /// split on a copy and compare): then the row sleeps and the ball,
    /// sliding on along the ground, does not.
    #[test]
    fn split_quick_check_keeps_a_joined_island_and_takes_off_a_lone_piece() {
        let mut world = World::new(WorldDef::default()).unwrap();
        let ground = world
            .create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0)))
            .unwrap();
        world
            .create_shape(ground, &ShapeDef::default(), Polygon::make_box(40.0, 1.0))
            .unwrap();
        let row: Vec<_> = (0..6)
            .map(|i| {
                let b = world
                    .create_body(&BodyDef::dynamic(Vec2::new(i as Real, 0.5)))
                    .unwrap();
                world
                    .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
                    .unwrap();
                b
            })
            .collect();
        let slider = world
            .create_body(&BodyDef {
                linear_velocity: Vec2::new(1.0, 0.0),
                ..BodyDef::dynamic(Vec2::new(0.0, 1.5))
            })
            .unwrap();
        let slippery = ShapeDef {
            friction: 0.0,
            ..ShapeDef::default()
        };
        world
            .create_shape(slider, &slippery, Circle::new(Vec2::ZERO, 0.5).unwrap())
            .unwrap();
        // Riding the row: four boxes left behind by t = 5 s (each seam
        // slows the ball a little; it leaves the row at x ≈ 6 by 9 s).
        for _ in 0..(5.0 / DT) as usize {
            world.step(DT).unwrap();
            assert!(
                !world.is_sleeping(row[0]).unwrap(),
                "the slider keeps the row awake"
            );
            assert_eq!(world.island_id(row[0]), world.island_id(slider));
        }
        let [whole, _] = world.islands.quick_splits;
        assert!(
            whole >= 3,
            "the quick check kept {whole} splits whole, not one a box"
        );
        for _ in 0..(8.0 / DT) as usize {
            world.step(DT).unwrap();
        }
        for &b in &row {
            assert!(
                world.is_sleeping(b).unwrap(),
                "the row sleeps once the slider left"
            );
        }
        assert!(!world.is_sleeping(slider).unwrap(), "the slider slides on");
        let [_, pieces] = world.islands.quick_splits;
        assert_eq!(pieces, 1, "the quick check took the ball off as one piece");
        assert_ne!(world.island_id(row[0]), world.island_id(slider));
        let v = world.linear_velocity(slider).unwrap();
        assert!(v.x > 0.5, "the slider keeps sliding: {v:?}");
    }
}
