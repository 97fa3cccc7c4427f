//! Graph colouring of constraints over the bodies they move.
//!
//! Two constraints of one colour never share a body whose state the solve
//! changes, so a colour's constraints can be solved in any order, in SIMD
//! lanes or on separate threads, with the result of a sequential sweep.
//! Static and kinematic bodies take no colour: the solve reads their state
//! but never changes it.
//!
//! ```text
//!   constraint      bodies        colour bits (a | b)   colour
//!   c0              1, 2          0000 | 0000           0
//!   c1              2, 3          0001 | 0000           1
//!   c2              3, ground     0010 | -              0
//!   c3              1, 3          0001 | 0011           2
//! ```
//!
//! Colouring is greedy in the order constraints are offered (the lowest
//! free colour); a constraint whose bodies already use all [`COLOURS`]
//! colours goes to the overflow set, solved one by one.
//!
//! Two forms: [`ColourGraph`] colours one step's constraints from scratch
//! (the joints, recoloured when one changes); [`ConstraintGraph`] keeps
//! each constraint's colour from step to step (the contacts: a contact
//! keeps its colour while it touches).

use std::sync::atomic::AtomicU32;
use std::sync::atomic::Ordering::Relaxed;

/// Number of colours.
pub const COLOURS: usize = 24;

/// The colour bits of every body state for one step's colouring.
#[derive(Clone, Debug, Default)]
pub struct ColourGraph {
    /// Bit `c` set: the body already appears in colour `c`.
    body_colours: Vec<u32>,
}

impl ColourGraph {
    /// An empty graph.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Clears every body's colours, for `state_count` body states.
    pub fn reset(&mut self, state_count: usize) {
        self.body_colours.clear();
        self.body_colours.resize(state_count, 0);
    }

    /// Assigns the lowest colour in which neither body appears and marks
    /// both in it; `None` for a body means it takes no colour (static or
    /// kinematic). Returns `None` when no colour is free (overflow), or
    /// when a state index is out of range.
    pub fn assign(&mut self, a: Option<u32>, b: Option<u32>) -> Option<usize> {
        let bits = |i: Option<u32>, colours: &[u32]| match i {
            Some(i) => colours.get(i as usize).copied(),
            None => Some(0),
        };
        let used = bits(a, &self.body_colours)? | bits(b, &self.body_colours)?;
        let colour = (!used).trailing_zeros() as usize;
        if colour >= COLOURS {
            return None;
        }
        for i in [a, b].into_iter().flatten() {
            self.body_colours[i as usize] |= 1 << colour;
        }
        Some(colour)
    }
}

/// The first colour a constraint with one moving body (against a static
/// or kinematic body) looks in ([`ConstraintGraph`]); pairs of moving
/// bodies look from colour 0.
pub const STATIC_FIRST: usize = COLOURS / 2;

/// No body: a side of a constraint that takes no colour.
pub const NO_BODY: u32 = u32::MAX;

/// A [`ConstraintGraph`] constraint's colour and the bodies it holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct GraphEntry {
    /// Its colour; [`GraphEntry::OUT`] when not in the graph,
    /// [`COLOURS`] when in the overflow.
    colour: u8,
    /// Body key of each side ([`NO_BODY`]: takes no colour).
    keys: [u32; 2],
}

impl GraphEntry {
    const OUT: u8 = u8::MAX;
    const VACANT: GraphEntry = GraphEntry {
        colour: Self::OUT,
        keys: [NO_BODY; 2],
    };
}

/// Per constraint id, the step it was last kept in (0: not kept). Atomic,
/// so that [`ConstraintGraph::keep_shared`] stamps from many threads at
/// once; a plain load or store on every target the engine builds for.
#[derive(Debug, Default)]
struct Stamps(Vec<AtomicU32>);

impl Clone for Stamps {
    fn clone(&self) -> Self {
        Stamps(
            self.0
                .iter()
                .map(|s| AtomicU32::new(s.load(Relaxed)))
                .collect(),
        )
    }
}

impl Stamps {
    /// Constraint `id`'s stamp (0 past the end).
    #[inline]
    fn get(&self, id: usize) -> u32 {
        self.0.get(id).map_or(0, |s| s.load(Relaxed))
    }

    /// Sets constraint `id`'s stamp (`id` within [`Stamps::cover`]).
    #[inline]
    fn set(&mut self, id: usize, stamp: u32) {
        *self.0[id].get_mut() = stamp;
    }

    /// Stamps for ids below `len` (new ones 0).
    fn cover(&mut self, len: usize) {
        if self.0.len() < len {
            self.0.resize_with(len, AtomicU32::default);
        }
    }
}

/// The persistent constraint graph: colours over the moving bodies that
/// last from step to step, as Box2D v3 keeps them.
///
/// A constraint (by a stable id: a contact's id) enters the graph the first
/// step it is solved and keeps its colour while its moving bodies stay the
/// same; it leaves when a step does not solve it (it stopped touching, was
/// destroyed, fell asleep, or a hook disabled it), or when its moving
/// bodies change (a body slept, woke or changed type), and then takes a
/// colour afresh. Bodies are keyed by something stable (a body's slot
/// index), not by the step's state index.
///
/// ```text
/// step n:    keep(c, keys) for every solved constraint, in a fixed order
///              same keys as stored, in a colour: that colour
///              otherwise: out (bits cleared), then the lowest free colour
///              (a pair with one moving body: from STATIC_FIRST up)
///            (or keep_shared(c, keys) on many threads first: the
///             constraints of the first case, stamped at once; the rest
///             through keep, in the same order)
///            sweep(): every entry not kept this step leaves (bits cleared)
/// ```
///
/// Pairs of two moving bodies fill the colours from the first, pairs with
/// one moving body (against the ground, say) from [`STATIC_FIRST`] (then
/// any free one), so that a forward sweep ends near the ground, which then
/// has the last word, as the per-step colouring did by colouring those
/// pairs after all the others. (From the last colour down, Box2D's order,
/// also kept the hard cases' figures, but reversed a body's ground
/// contacts against their contact order, and the rain ragdoll dropped
/// alone bounced off its ground instead of coming to rest.) A
/// constraint whose bodies already appear in every colour goes to the
/// overflow ([`COLOURS`]), and tries again each step.
#[derive(Clone, Debug, Default)]
pub struct ConstraintGraph {
    /// By body key: bit `c` set, the body appears in colour `c`.
    body_colours: Vec<u32>,
    /// By constraint id.
    entries: Vec<GraphEntry>,
    /// Ids with an entry in the graph (or the overflow), in the order they
    /// entered (the sweep's order).
    members: Vec<u32>,
    /// By constraint id: the step it was last kept in (in snapshots with
    /// its entry).
    stamps: Stamps,
    /// The current step's stamp.
    stamp: u32,
    /// Members kept (stamped) since [`ConstraintGraph::begin_step`]: when
    /// that is every member, the sweep has nothing to remove and skips its
    /// pass (a settled scene's usual step).
    kept: usize,
    /// By body key: colours held by other constraints this step (the
    /// joints', [`ConstraintGraph::set_reserved`]); no constraint of the
    /// graph takes one of them on that body.
    reserved: Vec<u32>,
    /// The reserved colours differ from the previous step's: only then
    /// can a kept constraint's colour meet one of them (it was checked
    /// against the same bits when it was last kept or coloured).
    reserved_changed: bool,
}

impl ConstraintGraph {
    /// An empty graph.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// The colours other constraints hold this step, by body key (bit `c`
    /// of `bits[k]`: body `k` is moved in colour `c` by a joint): a
    /// constraint kept afterwards takes none of them on its bodies, and
    /// one that holds such a colour takes another. Call before the step's
    /// [`ConstraintGraph::keep`]s; an empty slice reserves nothing.
    pub fn set_reserved(&mut self, bits: &[u32]) {
        self.reserved_changed = self.reserved.as_slice() != bits;
        if self.reserved_changed {
            self.reserved.clear();
            self.reserved.extend_from_slice(bits);
        }
    }

    /// The colours reserved on either key (see
    /// [`ConstraintGraph::set_reserved`]).
    #[inline]
    fn reserved_on(&self, keys: [u32; 2]) -> u32 {
        if self.reserved.is_empty() {
            // No joint holds a colour: nothing to look up per contact.
            return 0;
        }
        keys.iter()
            .filter(|&&k| k != NO_BODY)
            .map(|&k| self.reserved.get(k as usize).copied().unwrap_or(0))
            .fold(0, |a, b| a | b)
    }

    /// Starts a step: [`ConstraintGraph::keep`] then marks what stays.
    pub fn begin_step(&mut self) {
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            // Wrapped: stamps of 0 mean "not kept"; the rest restart.
            for s in &mut self.stamps.0 {
                *s.get_mut() = 0;
            }
            self.stamp = 1;
        }
        self.stamps.cover(self.entries.len());
        self.kept = 0;
    }

    /// Whether constraint `id` between the bodies with keys `keys` keeps
    /// its colour this step, as [`ConstraintGraph::keep`] would find: then
    /// it is stamped as kept and its colour returned, from any number of
    /// threads at once (each id once a step; tell the graph how many with
    /// [`ConstraintGraph::note_kept`]). `None`: it must go through `keep`
    /// (it is new, its bodies changed, or it waits in the overflow), in
    /// the same order as on one thread.
    #[must_use]
    pub fn keep_shared(&self, id: u32, keys: [u32; 2]) -> Option<u8> {
        let i = id as usize;
        let entry = *self.entries.get(i)?;
        let stamp = self.stamps.0.get(i)?;
        if entry.colour == GraphEntry::OUT
            || !self.keeps(entry, keys)
            || stamp.load(Relaxed) == self.stamp
        {
            return None;
        }
        stamp.store(self.stamp, Relaxed);
        Some(entry.colour)
    }

    /// Counts `count` constraints kept by [`ConstraintGraph::keep_shared`].
    pub fn note_kept(&mut self, count: usize) {
        self.kept += count;
    }

    /// Whether an entry in the graph keeps its colour for `keys`.
    #[inline]
    fn keeps(&self, entry: GraphEntry, keys: [u32; 2]) -> bool {
        entry.keys == keys
            && (entry.colour as usize) < COLOURS
            && (!self.reserved_changed || self.reserved_on(keys) & (1 << entry.colour) == 0)
    }

    /// Asks for constraint `id`'s graph entry and stamp ahead of a
    /// [`ConstraintGraph::keep`] (ids are in no order: each is two random
    /// reads).
    #[inline]
    pub fn prefetch(&self, id: u32) {
        let i = id as usize;
        if let Some(entry) = self.entries.get(i) {
            crate::hint::prefetch(entry);
        }
        if let Some(stamp) = self.stamps.0.get(i) {
            crate::hint::prefetch(stamp);
        }
    }

    /// The colour of constraint `id` between the bodies with keys `keys`
    /// ([`NO_BODY`] for a side that takes no colour) this step: the one it
    /// had if its keys are unchanged, otherwise a new one. Returns
    /// [`COLOURS`] for the overflow.
    pub fn keep(&mut self, id: u32, keys: [u32; 2]) -> u8 {
        let i = id as usize;
        if self.entries.len() <= i {
            self.entries.resize(i + 1, GraphEntry::VACANT);
        }
        self.stamps.cover(i + 1);
        let entry = self.entries[i];
        if entry.colour != GraphEntry::OUT {
            // (A second keep of the same id in a step counts once.)
            self.kept += usize::from(self.stamps.get(i) != self.stamp);
            if self.keeps(entry, keys) {
                self.stamps.set(i, self.stamp);
                return entry.colour;
            }
            // Its bodies changed, or it waits in the overflow: again.
            self.clear_bits(entry);
        } else {
            self.members.push(id);
            self.kept += 1;
        }
        let colour = self.find_colour(keys);
        if (colour as usize) < COLOURS {
            for k in keys {
                if k != NO_BODY {
                    self.body_colours[k as usize] |= 1 << colour;
                }
            }
        }
        self.entries[i] = GraphEntry { colour, keys };
        self.stamps.set(i, self.stamp);
        colour
    }

    /// Every constraint not kept since [`ConstraintGraph::begin_step`]
    /// leaves the graph (its bodies' colour bits are cleared).
    pub fn sweep(&mut self) {
        if self.kept == self.members.len() {
            return;
        }
        let mut members = std::mem::take(&mut self.members);
        members.retain(|&id| {
            let entry = self.entries[id as usize];
            if self.stamps.get(id as usize) == self.stamp {
                return true;
            }
            self.clear_bits(entry);
            self.entries[id as usize] = GraphEntry::VACANT;
            false
        });
        self.members = members;
    }

    /// Number of constraints in the graph (overflow included).
    #[must_use]
    pub fn len(&self) -> usize {
        self.members.len()
    }

    /// True when no constraint is in the graph.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.members.is_empty()
    }

    /// Checks that every body's bits are exactly the colours of the
    /// constraints that hold it, and that no colour holds a body twice
    /// (for tests and snapshot validation).
    pub fn check(&self) -> Result<(), String> {
        let mut bits = vec![0u32; self.body_colours.len()];
        for &id in &self.members {
            let e = self
                .entries
                .get(id as usize)
                .ok_or_else(|| format!("member {id} has no entry"))?;
            if e.colour == GraphEntry::OUT {
                return Err(format!("member {id} is out of the graph"));
            }
            if (e.colour as usize) < COLOURS {
                for k in e.keys {
                    if k == NO_BODY {
                        continue;
                    }
                    let b = bits
                        .get_mut(k as usize)
                        .ok_or_else(|| format!("member {id}: body key {k} out of range"))?;
                    if *b & (1 << e.colour) != 0 {
                        return Err(format!("body {k} twice in colour {}", e.colour));
                    }
                    *b |= 1 << e.colour;
                }
            }
        }
        if bits != self.body_colours[..bits.len()] {
            return Err("body colour bits differ from the members' colours".into());
        }
        // Every entry in the graph is a member, once, of a colour or the
        // overflow; the others are out. (A decoded snapshot's entry of
        // colour 251 outside the members passed the check above and was
        // then taken for a member by `keep`.)
        let mut seen = vec![false; self.entries.len()];
        for &id in &self.members {
            if std::mem::replace(&mut seen[id as usize], true) {
                return Err(format!("member {id} listed twice"));
            }
        }
        let mut in_graph = 0usize;
        for e in &self.entries {
            if e.colour != GraphEntry::OUT {
                if e.colour as usize > COLOURS {
                    return Err(format!("an entry of colour {}", e.colour));
                }
                in_graph += 1;
            }
        }
        if in_graph != self.members.len() {
            return Err(format!(
                "{in_graph} entries in the graph, {} members",
                self.members.len()
            ));
        }
        Ok(())
    }

    fn clear_bits(&mut self, entry: GraphEntry) {
        if (entry.colour as usize) < COLOURS {
            for k in entry.keys {
                if let Some(b) = self.body_colours.get_mut(k as usize) {
                    *b &= !(1 << entry.colour);
                }
            }
        }
    }

    /// The lowest colour (both sides move) or the highest (one side
    /// moves) in which no keyed body appears; [`COLOURS`] when none.
    fn find_colour(&mut self, keys: [u32; 2]) -> u8 {
        let mut used = self.reserved_on(keys);
        let mut moving = 0;
        for k in keys {
            if k != NO_BODY {
                let k = k as usize;
                if self.body_colours.len() <= k {
                    self.body_colours.resize(k + 1, 0);
                }
                used |= self.body_colours[k];
                moving += 1;
            }
        }
        let free = !used & ((1u32 << COLOURS) - 1);
        if free == 0 {
            return COLOURS as u8;
        }
        // Pairs with one moving body look from STATIC_FIRST up first.
        let late = free & !((1u32 << STATIC_FIRST) - 1);
        if moving < 2 && late != 0 {
            late.trailing_zeros() as u8
        } else {
            free.trailing_zeros() as u8
        }
    }
}

/// The graph as snapshots hold it: each entry with its stamp (the layout
/// from before the stamps moved apart, so snapshots kept their format).
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
struct StoredGraph {
    body_colours: Vec<u32>,
    entries: Vec<StoredEntry>,
    members: Vec<u32>,
    stamp: u32,
}

/// A [`GraphEntry`] and its stamp, as snapshots hold them.
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
struct StoredEntry {
    colour: u8,
    stamp: u32,
    keys: [u32; 2],
}

#[cfg(feature = "serde")]
impl serde::Serialize for ConstraintGraph {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let entries = self
            .entries
            .iter()
            .enumerate()
            .map(|(i, e)| StoredEntry {
                colour: e.colour,
                stamp: self.stamps.get(i),
                keys: e.keys,
            })
            .collect();
        let stored = StoredGraph {
            body_colours: self.body_colours.clone(),
            entries,
            members: self.members.clone(),
            stamp: self.stamp,
        };
        stored.serialize(serializer)
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for ConstraintGraph {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let stored = StoredGraph::deserialize(deserializer)?;
        let stamps = stored
            .entries
            .iter()
            .map(|e| AtomicU32::new(e.stamp))
            .collect();
        let entries = stored
            .entries
            .iter()
            .map(|e| GraphEntry {
                colour: e.colour,
                keys: e.keys,
            })
            .collect();
        Ok(ConstraintGraph {
            body_colours: stored.body_colours,
            entries,
            members: stored.members,
            stamps: Stamps(stamps),
            stamp: stored.stamp,
            ..ConstraintGraph::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_colour_never_holds_a_moving_body_twice() {
        let mut g = ColourGraph::new();
        g.reset(4);
        assert_eq!(g.assign(Some(1), Some(2)), Some(0));
        assert_eq!(g.assign(Some(2), Some(3)), Some(1));
        assert_eq!(g.assign(Some(3), None), Some(0));
        assert_eq!(g.assign(Some(1), Some(3)), Some(2));
        // Bodies that take no colour never block one.
        assert_eq!(g.assign(None, None), Some(0));
    }

    #[test]
    fn a_body_in_every_colour_overflows() {
        let mut g = ColourGraph::new();
        g.reset(COLOURS + 2);
        for k in 0..COLOURS {
            assert_eq!(g.assign(Some(0), Some(k as u32 + 1)), Some(k));
        }
        assert_eq!(g.assign(Some(0), Some(COLOURS as u32 + 1)), None);
        assert_eq!(g.assign(Some(99), None), None, "out of range");
    }

    #[test]
    fn graph_keeps_colours_between_steps_and_frees_them_when_not_kept() {
        let mut g = ConstraintGraph::new();
        g.begin_step();
        assert_eq!(g.keep(0, [1, 2]), 0);
        assert_eq!(g.keep(1, [2, 3]), 1);
        // One moving body: from STATIC_FIRST up.
        assert_eq!(g.keep(2, [3, NO_BODY]), STATIC_FIRST as u8);
        assert_eq!(g.keep(3, [NO_BODY, 3]), STATIC_FIRST as u8 + 1);
        g.sweep();
        g.check().unwrap();
        // Next step, in another order: the same colours.
        g.begin_step();
        assert_eq!(g.keep(3, [NO_BODY, 3]), STATIC_FIRST as u8 + 1);
        assert_eq!(g.keep(1, [2, 3]), 1);
        assert_eq!(g.keep(0, [1, 2]), 0);
        g.sweep();
        g.check().unwrap();
        assert_eq!(g.len(), 3, "constraint 2 was not kept: it left");
        // Its colour is free again for body 3.
        g.begin_step();
        assert_eq!(g.keep(9, [3, NO_BODY]), STATIC_FIRST as u8);
        // A constraint whose bodies changed is coloured afresh.
        // (its old colour is freed first, so colour 0 serves again).
        assert_eq!(g.keep(0, [1, 4]), 0);
        assert_eq!(g.keep(5, [2, 4]), 2, "body 2 is in 1, body 4 in 0");
        g.sweep();
        g.check().unwrap();
    }

    #[test]
    fn graph_overflows_when_a_body_is_in_every_colour_and_retries() {
        let mut g = ConstraintGraph::new();
        g.begin_step();
        for k in 0..COLOURS as u32 {
            assert_eq!(g.keep(k, [0, k + 1]), k as u8);
        }
        let extra = COLOURS as u32;
        assert_eq!(g.keep(extra, [0, extra + 1]), COLOURS as u8);
        g.sweep();
        g.check().unwrap();
        // Next step one of body 0's constraints is gone: the overflowed
        // one takes its colour.
        g.begin_step();
        for k in 1..COLOURS as u32 {
            g.keep(k, [0, k + 1]);
        }
        g.sweep();
        g.begin_step();
        assert_eq!(g.keep(extra, [0, extra + 1]), 0);
        g.check().unwrap();
    }

    /// Keeping shared where it can, then the rest in order, leaves the
    /// graph as keeping every constraint in order does: the same colours,
    /// the same members after the sweep.
    #[test]
    fn keeping_shared_then_in_order_colours_as_keeping_in_order() {
        // Step 1: a chain of bodies and a few ground contacts.
        let first: Vec<(u32, [u32; 2])> = (0..40)
            .map(|k| (k, if k % 7 == 0 { [k, NO_BODY] } else { [k, k + 1] }))
            .collect();
        // Step 2: 5 and 12 leave, 3 and 20 change bodies, 41 and 42 are new.
        let second: Vec<(u32, [u32; 2])> = first
            .iter()
            .filter(|(id, _)| *id != 5 && *id != 12)
            .map(|&(id, keys)| match id {
                3 => (id, [3, 30]),
                20 => (id, [20, 2]),
                _ => (id, keys),
            })
            .chain([(41, [5, 6]), (42, [12, NO_BODY])])
            .collect();
        let mut in_order = ConstraintGraph::new();
        let mut shared = ConstraintGraph::new();
        for g in [&mut in_order, &mut shared] {
            g.begin_step();
            for &(id, keys) in &first {
                g.keep(id, keys);
            }
            g.sweep();
        }
        in_order.begin_step();
        let expected: Vec<u8> = second
            .iter()
            .map(|&(id, keys)| in_order.keep(id, keys))
            .collect();
        in_order.sweep();
        shared.begin_step();
        let kept: Vec<Option<u8>> = second
            .iter()
            .map(|&(id, keys)| shared.keep_shared(id, keys))
            .collect();
        assert_eq!(
            kept.iter().filter(|k| k.is_none()).count(),
            4,
            "3, 20, 41 and 42 go in order"
        );
        shared.note_kept(kept.iter().filter(|k| k.is_some()).count());
        let colours: Vec<u8> = second
            .iter()
            .zip(&kept)
            .map(|(&(id, keys), k)| k.unwrap_or_else(|| shared.keep(id, keys)))
            .collect();
        shared.sweep();
        assert_eq!(colours, expected);
        assert_eq!(shared.len(), in_order.len());
        assert_eq!(shared.members, in_order.members);
        assert_eq!(shared.body_colours, in_order.body_colours);
        shared.check().unwrap();
    }

    #[test]
    fn sweep_skip_counts_a_constraint_kept_twice_in_a_step_once() {
        let mut g = ConstraintGraph::new();
        g.begin_step();
        g.keep(0, [1, 2]);
        g.keep(1, [3, 4]);
        g.sweep();
        assert_eq!(g.len(), 2);
        // Constraint 0 kept twice, constraint 1 not at all: two keeps
        // for two members, yet 1 must leave.
        g.begin_step();
        assert_eq!(g.keep(0, [1, 2]), 0);
        assert_eq!(g.keep(0, [1, 2]), 0);
        g.sweep();
        g.check().unwrap();
        assert_eq!(g.len(), 1, "constraint 1 was not kept: it left");
        // Every member kept: the sweep keeps them all.
        g.begin_step();
        g.keep(0, [1, 2]);
        g.sweep();
        assert_eq!(g.len(), 1);
        g.check().unwrap();
    }

    #[test]
    fn a_kept_colour_yields_to_a_new_reservation_and_stays_under_the_same_one() {
        let mut g = ConstraintGraph::new();
        g.begin_step();
        assert_eq!(g.keep(0, [1, 2]), 0);
        g.sweep();
        // A joint now holds colour 0 on body 2: the contact moves on.
        let mut bits = vec![0u32; 4];
        bits[2] = 1;
        g.set_reserved(&bits);
        g.begin_step();
        let moved = g.keep(0, [1, 2]);
        assert_ne!(moved, 0);
        g.sweep();
        g.check().unwrap();
        // The same reservation next step: the contact keeps its new colour
        // (the per-contact check is skipped, the answer is the same).
        g.set_reserved(&bits);
        g.begin_step();
        assert_eq!(g.keep(0, [1, 2]), moved);
        // A constraint coloured afresh still avoids the reserved colour.
        assert_ne!(g.keep(1, [2, 3]), 0);
        g.sweep();
        g.check().unwrap();
        // The reservation moves to the contact's colour: it moves again.
        let mut bits2 = vec![0u32; 4];
        bits2[1] = 1 << moved;
        g.set_reserved(&bits2);
        g.begin_step();
        assert_ne!(g.keep(0, [1, 2]), moved);
    }
}
