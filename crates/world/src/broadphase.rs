//! Broadphase: finds the pairs of shapes whose bounding boxes overlap.
//!
//! # Structure
//!
//! The broadphase is built on [`DynamicTree`] (see
//! [`dynamic_tree`](crate::dynamic_tree)), an incremental bounding-volume
//! hierarchy whose leaves are **fat** boxes: the shape's tight box grown by a
//! margin (at most [`DEFAULT_AABB_MARGIN`] = 0.1 m; the world gives a small
//! shape a smaller one, sized by its extent: see
//! [`proxy_margin`]). As long as the tight box
//! stays inside the fat one, moving the shape costs one containment test and
//! the tree is not touched. Only when the tight box leaves the fat box is the
//! leaf removed and re-inserted, and only then can new pairs appear, so only
//! those proxies are queried for pairs.
//!
//! [`BroadPhase`] keeps two trees, one for static proxies (never fattened)
//! and one for movable ones, so static–static pairs are never even visited.
//! New pairs are found by querying the trees with the fat box of each moved
//! proxy; when at least a quarter of the proxies moved (first step, a scene
//! being loaded) one simultaneous descent of the trees against themselves is
//! used instead, which visits every overlapping pair once for less work than
//! `n` separate queries.
//!
//! # Why this structure
//!
//! | need                                   | how the dynamic tree meets it                         |
//! |----------------------------------------|-------------------------------------------------------|
//! | most bodies move a little every step   | fat boxes: a small move is one `contains` test        |
//! | bodies appear / vanish at any time     | O(log n) insert and remove, no global rebuild         |
//! | tens of thousands of proxies           | O(log n + k) queries, height kept near `log2 n`       |
//! | everything moved at once               | one tree-against-tree descent instead of n queries    |
//! | sparse and clustered scenes alike      | adaptive, no cell size to tune (unlike a grid)        |
//! | large static worlds                    | separate static tree, static pairs never tested       |
//! | reproducible simulations               | no hashing, no pointers: output sorted, ids stable    |
//!
//! # Pairs
//!
//! [`BroadPhase::update_pairs`] reports the candidate pairs of every proxy
//! whose fat box was re-inserted (or that was created) since the last call.
//! The broadphase keeps no pair set; **pair persistence is the caller's job**,
//! as in Box2D:
//!
//! - a reported pair may already have a contact (a re-inserted proxy still
//!   overlapping an old partner): the caller ignores pairs it already holds;
//! - a contact stays until [`BroadPhase::test_overlap`] says that the two fat
//!   boxes no longer overlap; then the caller destroys it.
//!
//! With these two rules the caller's pair set always equals the set of
//! overlapping fat boxes (minus the pairs its filter rejected).

use janus2d_core::geometry::Aabb;
use janus2d_core::math::{Real, Vec2};
use janus2d_core::parallel::Team;

pub use crate::dynamic_tree::{
    BulkFinish, DEFAULT_AABB_MARGIN, DynamicTree, FilterBits, NULL_NODE,
};

/// [`BroadPhase::update_pairs`] switches from per-proxy queries to one
/// simultaneous tree descent when at least `1 / BULK_DIVISOR` of the proxies
/// moved.
const BULK_DIVISOR: usize = 4;

/// Fewest moved proxies for which the pair search runs in blocks on the
/// step's team (of more than one thread).
const PARALLEL_MOVES: usize = 256;

/// Per-proxy record of the [`BroadPhase`].
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct ProxySlot {
    /// The fat box of the leaf, kept here too so that the narrowphase's
    /// overlap test per contact reads one slot instead of slot and node.
    fat: Aabb,
    /// The fat box without the velocity sweep (the tight box grown by the
    /// margin when last moved): two movable proxies pair, and keep their
    /// pair, only while these overlap, and a proxy counts as moved when its
    /// tight box leaves it. Equal to `fat` for a static proxy, for one that
    /// was not swept, and in a world with uniform margins.
    core: Aabb,
    /// Leaf id in the tree selected by `is_static`.
    leaf: u32,
    /// User payload (a shape key).
    payload: u32,
    /// Lives in the static tree.
    is_static: bool,
    /// Created or re-inserted since the last [`BroadPhase::update_pairs`].
    moved: bool,
    /// False once destroyed (the slot is on the free list).
    alive: bool,
    /// The proxy's own fat-box margin, metres (at most its tree's).
    margin: Real,
}

/// The broadphase: proxies in two [`DynamicTree`]s (static and movable) and
/// the incremental search for new overlapping pairs.
///
/// Proxies are addressed by a `u32` proxy id (stable until destroyed, reused
/// afterwards) and carry a `u32` payload, normally a shape key. Static
/// proxies use a zero margin (they do not move) and are never tested against
/// each other.
///
/// Typical step:
/// 1. [`move_proxy`](Self::move_proxy) every awake shape with its new tight
///    box;
/// 2. [`update_pairs`](Self::update_pairs) to get the new candidate pairs and
///    create contacts for them;
/// 3. drop existing contacts whose proxies no longer overlap according to
///    [`test_overlap`](Self::test_overlap). Pair persistence is the caller's
///    job, as in Box2D: the broadphase keeps no pair set.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BroadPhase {
    dynamic_tree: DynamicTree,
    static_tree: DynamicTree,
    proxies: Vec<ProxySlot>,
    free_proxies: Vec<u32>,
    /// The proxies moved since the last pair update, in the order they
    /// moved. Nothing reads the order: the pair update marks and queries
    /// each and sorts what it finds, and the tree's growth is a union. So
    /// the proxy update may fill it in any order (by body on one thread,
    /// by shape slot on a team), and a snapshot writes it sorted.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_maps::sorted_ids"))]
    move_buffer: Vec<u32>,
    /// Scratch stack of the simultaneous tree descent.
    pair_stack: Vec<(u32, u32)>,
    /// Scratch of the dynamic tree's partial rebuild.
    #[cfg_attr(feature = "serde", serde(skip))]
    rebuild_items: Vec<(Vec2, u32)>,
    /// Scratch of the bulk pair search: per node of each tree (dynamic,
    /// static), whether its subtree holds a moved proxy.
    #[cfg_attr(feature = "serde", serde(skip))]
    moved_marks: [Vec<bool>; 2],
    /// Every movable proxy takes the tree's whole margin, whatever margin
    /// its creator asked for (see [`BroadPhase::use_uniform_margin`]).
    uniform_margin: bool,
}

impl Default for BroadPhase {
    fn default() -> Self {
        Self::new()
    }
}

impl BroadPhase {
    /// An empty broadphase with the default margin [`DEFAULT_AABB_MARGIN`]
    /// (0.1 m) for movable proxies.
    pub fn new() -> Self {
        Self::with_margin(DEFAULT_AABB_MARGIN)
    }

    /// An empty broadphase whose movable proxies are fattened by `margin`
    /// metres (static proxies are never fattened).
    pub fn with_margin(margin: Real) -> Self {
        BroadPhase {
            dynamic_tree: DynamicTree::with_margin(margin),
            static_tree: DynamicTree::with_margin(0.0),
            proxies: Vec::new(),
            free_proxies: Vec::new(),
            move_buffer: Vec::new(),
            moved_marks: [Vec::new(), Vec::new()],
            uniform_margin: false,
            pair_stack: Vec::new(),
            rebuild_items: Vec::new(),
        }
    }

    /// The fat-box margin of movable proxies, in metres.
    #[inline]
    pub fn margin(&self) -> Real {
        self.dynamic_tree.margin()
    }

    /// Number of live proxies.
    #[inline]
    pub fn proxy_count(&self) -> usize {
        self.proxies.len() - self.free_proxies.len()
    }

    /// The tree holding the movable proxies.
    #[inline]
    pub fn dynamic_tree(&self) -> &DynamicTree {
        &self.dynamic_tree
    }

    /// The tree holding the static proxies.
    #[inline]
    pub fn static_tree(&self) -> &DynamicTree {
        &self.static_tree
    }

    #[cfg(test)]
    /// Adds a proxy for the tight box `aabb` with the given payload and
    /// returns its id. The new proxy counts as moved: its pairs are reported
    /// by the next [`update_pairs`](Self::update_pairs).
    pub fn create_proxy(&mut self, aabb: Aabb, payload: u32, is_static: bool) -> u32 {
        self.create_proxy_with_margin(aabb, payload, is_static, Real::INFINITY)
    }

    /// [`create_proxy`](Self::create_proxy) whose fat boxes grow the tight
    /// box by `margin` metres, or by the tree's margin if that is smaller
    /// (static proxies: 0). Small shapes take small margins, so that the
    /// fat boxes of a dense pile of them do not overlap far beyond their
    /// neighbours (see [`proxy_margin`]).
    #[cfg(test)]
    pub fn create_proxy_with_margin(
        &mut self,
        aabb: Aabb,
        payload: u32,
        is_static: bool,
        margin: Real,
    ) -> u32 {
        self.create_proxy_filtered(aabb, payload, is_static, margin, FilterBits::ALL)
    }

    /// Adds a proxy for the tight box `aabb` with the given payload, whose
    /// fat boxes grow the tight box by `margin` metres (at most the tree's
    /// margin; static proxies: 0), for a shape whose collision filter
    /// gives `bits` ([`FilterBits::of`]): the pair search skips the
    /// proxies it cannot pair with. The new proxy counts as moved.
    pub fn create_proxy_filtered(
        &mut self,
        aabb: Aabb,
        payload: u32,
        is_static: bool,
        margin: Real,
        bits: FilterBits,
    ) -> u32 {
        let full = self.tree(is_static).margin();
        let margin = if self.uniform_margin {
            full
        } else {
            margin.min(full).max(0.0)
        };
        let id = match self.free_proxies.pop() {
            Some(id) => id,
            None => {
                let id = u32::try_from(self.proxies.len()).expect("too many proxies");
                self.proxies.push(ProxySlot {
                    fat: aabb,
                    core: aabb,
                    leaf: NULL_NODE,
                    payload: 0,
                    is_static: false,
                    moved: false,
                    alive: false,
                    margin: 0.0,
                });
                id
            }
        };
        let tree = if is_static {
            &mut self.static_tree
        } else {
            &mut self.dynamic_tree
        };
        let leaf = tree.create_proxy_filtered(aabb, id, margin, bits);
        self.proxies[id as usize] = ProxySlot {
            fat: tree.fat_aabb(leaf),
            core: tree.fat_aabb(leaf),
            leaf,
            payload,
            is_static,
            moved: true,
            alive: true,
            margin,
        };
        self.move_buffer.push(id);
        id
    }

    /// Removes a proxy. Its pairs are not reported any more; contacts that
    /// the caller holds for it must be destroyed by the caller.
    pub fn destroy_proxy(&mut self, proxy: u32) {
        if proxy == NO_PROXY {
            return;
        }
        let slot = self.slot(proxy);
        self.tree_mut(slot.is_static).destroy_proxy(slot.leaf);
        let s = &mut self.proxies[proxy as usize];
        s.alive = false;
        s.moved = false;
        s.leaf = NULL_NODE;
        // A stale entry may remain in the move buffer; update_pairs skips it.
        self.free_proxies.push(proxy);
    }

    /// Updates a proxy with its new tight box. Returns `true` when the fat box
    /// had to be re-inserted; the proxy is then marked as moved and its new
    /// pairs are reported by the next [`update_pairs`](Self::update_pairs).
    pub fn move_proxy(&mut self, proxy: u32, aabb: Aabb) -> bool {
        if proxy == NO_PROXY {
            return false;
        }
        let slot = self.slot(proxy);
        if slot.fat.contains(&aabb) {
            // Still inside its fat box: the tree is not touched.
            return false;
        }
        let tree = self.tree_mut(slot.is_static);
        let reinserted = tree.move_proxy_with_margin(slot.leaf, aabb, slot.margin);
        if reinserted {
            let fat = tree.fat_aabb(slot.leaf);
            self.proxies[proxy as usize].fat = fat;
            self.proxies[proxy as usize].core = fat;
            self.mark_moved(proxy);
        }
        reinserted
    }

    /// [`move_proxy`](Self::move_proxy) for one of a batch of moves: a
    /// movable proxy's tree is not restructured per move (see
    /// [`DynamicTree::enlarge_proxy`]); [`finish_moves`](Self::finish_moves)
    /// must follow the batch, before any query or pair search.
    pub fn move_proxy_in_batch(&mut self, proxy: u32, aabb: Aabb) -> bool {
        let slot = self.slot(proxy);
        if slot.fat.contains(&aabb) {
            return false;
        }
        if slot.is_static {
            return self.move_proxy(proxy, aabb);
        }
        let moved = self
            .dynamic_tree
            .enlarge_leaf_with_margin(slot.leaf, aabb, slot.margin);
        if moved {
            let fat = self.dynamic_tree.fat_aabb(slot.leaf);
            self.proxies[proxy as usize].fat = fat;
            self.proxies[proxy as usize].core = fat;
            self.mark_moved(proxy);
        }
        moved
    }

    /// [`move_proxy_in_batch`](Self::move_proxy_in_batch) for a shape with
    /// tight box `tight` that moves by `sweep` in a step. When that is more
    /// than half the proxy's margin, the tree box covers the swept box
    /// `query` (the tight box and where the velocity takes it), so that
    /// pairs exist before the shape arrives; otherwise `query` is `tight`.
    /// Pairs with other movable proxies follow `tight` alone: the tree box
    /// is enlarged when `query` leaves it, and the core box is `tight`
    /// grown by the margin, renewed (and the proxy counted as moved)
    /// whenever `tight` leaves it. For a proxy never swept the two boxes
    /// are one and this is `move_proxy_in_batch(proxy, tight)`; for a proxy
    /// with the tree's whole margin (a large shape, or any shape in a world
    /// with uniform margins) it is `move_proxy_in_batch(proxy, query)`: the
    /// split is for small shapes, which then pair with other movable shapes
    /// as in Box2D (sized margin, no sweep) and with static ones through
    /// their swept box.
    pub fn move_proxy_in_batch_swept(&mut self, proxy: u32, tight: Aabb, sweep: Vec2) -> bool {
        let slot = self.slot(proxy);
        let query = swept_query(&slot, tight, sweep);
        if self.one_box(&slot) {
            return self.move_proxy_in_batch(proxy, query);
        }
        let mut moved = false;
        if !slot.fat.contains(&query)
            && self
                .dynamic_tree
                .enlarge_leaf_with_margin(slot.leaf, query, slot.margin)
        {
            self.proxies[proxy as usize].fat = self.dynamic_tree.fat_aabb(slot.leaf);
            moved = true;
        }
        if !moved && !slot.core.contains(&tight) {
            // A new core must lie inside the tree box, or a pair it makes
            // would not be found: the tree box grows to the swept box with
            // its margin unless it holds that already.
            if self.dynamic_tree.enlarge_leaf_with_margin(
                slot.leaf,
                query.fattened(slot.margin),
                0.0,
            ) {
                self.proxies[proxy as usize].fat = self.dynamic_tree.fat_aabb(slot.leaf);
            }
            moved = true;
        }
        if moved {
            self.proxies[proxy as usize].core = tight.fattened(slot.margin);
            self.mark_moved(proxy);
        }
        moved
    }

    /// True when [`move_proxy_in_batch_swept`](Self::move_proxy_in_batch_swept)
    /// with these arguments would change nothing: its boxes hold the
    /// shape's. Reads only, so a pass on threads can ask it for every shape
    /// and leave the (few) moves to the caller, in order.
    #[must_use]
    pub fn keeps_boxes(&self, proxy: u32, tight: Aabb, sweep: Vec2) -> bool {
        let slot = self.slot(proxy);
        slot.fat.contains(&swept_query(&slot, tight, sweep))
            && (self.one_box(&slot) || slot.core.contains(&tight))
    }

    /// Static proxies do not move; a proxy with the tree's whole margin (a
    /// large shape, or any in a world with uniform margins) keeps one box,
    /// swept, for all its pairs.
    #[inline]
    fn one_box(&self, slot: &ProxySlot) -> bool {
        slot.is_static || self.uniform_margin || slot.margin >= self.dynamic_tree.margin()
    }

    /// Ends a batch of [`move_proxy_in_batch`](Self::move_proxy_in_batch):
    /// the movable proxies' tree is rebuilt where the moves grew it, or
    /// whole when many moved ([`DynamicTree::finish_enlarged`]), on the
    /// caller.
    pub fn finish_moves(&mut self) {
        self.finish_moves_with(&Team::serial(), BulkFinish::Rebuild);
    }

    /// [`finish_moves`](Self::finish_moves), a batch of many moves finished
    /// as `bulk` says: rebuilt, its spans on `team` (the tree is the same
    /// for any team), or refitted in its shape.
    pub fn finish_moves_with(&mut self, team: &Team, bulk: BulkFinish) {
        self.dynamic_tree
            .finish_enlarged_with(&mut self.rebuild_items, team, bulk);
    }

    /// Whether the batch so far moved enough proxies for
    /// [`finish_moves`](Self::finish_moves) to rebuild the whole tree
    /// ([`DynamicTree::pending_is_bulk`]): worth doing on a team.
    #[must_use]
    pub fn moves_are_bulk(&self) -> bool {
        self.dynamic_tree.pending_is_bulk()
    }

    /// True when `proxy` names a live proxy (never panics; for checks).
    #[must_use]
    pub fn is_live(&self, proxy: u32) -> bool {
        self.proxies.get(proxy as usize).is_some_and(|s| s.alive)
    }

    /// Gives a proxy the filter bits of its shape's new filter (see
    /// [`FilterBits`]); [`touch_proxy`](Self::touch_proxy) then has its
    /// pairs found again under it.
    pub fn set_proxy_bits(&mut self, proxy: u32, bits: FilterBits) {
        if !self.is_live(proxy) {
            return;
        }
        let slot = self.slot(proxy);
        self.tree_mut(slot.is_static)
            .set_proxy_bits(slot.leaf, bits);
    }

    /// Marks a proxy as moved without changing its box, so that the next
    /// [`update_pairs`](Self::update_pairs) reports all its pairs again (for
    /// instance after its collision filter changed).
    pub fn touch_proxy(&mut self, proxy: u32) {
        if proxy == NO_PROXY {
            return;
        }
        self.slot(proxy);
        self.mark_moved(proxy);
    }

    #[cfg(test)]
    /// True when the proxy was created, re-inserted or touched since the last
    /// [`update_pairs`](Self::update_pairs).
    pub fn is_moved(&self, proxy: u32) -> bool {
        self.slot(proxy).moved
    }

    /// The fat box of a proxy.
    pub fn fat_aabb(&self, proxy: u32) -> Aabb {
        self.slot(proxy).fat
    }

    /// The fat-box margin of a proxy, metres.
    #[cfg(test)]
    pub fn proxy_margin(&self, proxy: u32) -> Real {
        self.slot(proxy).margin
    }

    /// From now on every movable proxy has the tree's whole margin: those
    /// with a smaller one are re-inserted at once with their tight box
    /// `tight_of(payload)` fattened by it (in proxy order, each marked as
    /// moved), and later proxies are created with it.
    #[cfg_attr(not(feature = "portals"), allow(dead_code))]
    pub fn use_uniform_margin(&mut self, tight_of: impl Fn(u32) -> Aabb) {
        if self.uniform_margin {
            return;
        }
        self.uniform_margin = true;
        let full = self.dynamic_tree.margin();
        for proxy in 0..self.proxies.len() as u32 {
            let slot = self.proxies[proxy as usize];
            if !slot.alive || slot.is_static || slot.margin >= full {
                continue;
            }
            let tight = tight_of(slot.payload);
            let bits = self.dynamic_tree.proxy_bits(slot.leaf);
            self.dynamic_tree.destroy_proxy(slot.leaf);
            let leaf = self
                .dynamic_tree
                .create_proxy_filtered(tight, proxy, full, bits);
            let s = &mut self.proxies[proxy as usize];
            s.leaf = leaf;
            s.margin = full;
            s.fat = self.dynamic_tree.fat_aabb(leaf);
            s.core = s.fat;
            self.mark_moved(proxy);
        }
    }

    /// The payload of a proxy.
    pub fn payload(&self, proxy: u32) -> u32 {
        self.slot(proxy).payload
    }

    /// Gives a live proxy a new payload (its boxes and trees unchanged):
    /// the shape store moved the proxy's shape to another slot.
    #[cfg_attr(not(feature = "portals"), allow(dead_code))]
    pub(crate) fn set_payload(&mut self, proxy: u32, payload: u32) {
        if let Some(slot) = self.proxies.get_mut(proxy as usize)
            && slot.alive
        {
            slot.payload = payload;
        }
    }

    /// True for a proxy created as static.
    pub fn is_static(&self, proxy: u32) -> bool {
        self.slot(proxy).is_static
    }

    /// True when the fat boxes of two proxies overlap (touching counts). A
    /// caller keeps a contact while this holds.
    pub fn test_overlap(&self, proxy_a: u32, proxy_b: u32) -> bool {
        pair_overlaps(&self.slot(proxy_a), &self.slot(proxy_b))
    }

    /// Calls `callback(proxy, payload)` for every proxy (static or not) whose
    /// fat box overlaps `aabb`, until the callback returns `false`. Movable
    /// proxies are visited first.
    pub fn query<F: FnMut(u32, u32) -> bool>(&self, aabb: &Aabb, mut callback: F) {
        let proxies = &self.proxies;
        let mut go_on = true;
        for tree in [&self.dynamic_tree, &self.static_tree] {
            if !go_on {
                break;
            }
            tree.query(aabb, |proxy| {
                go_on = callback(proxy, proxies[proxy as usize].payload);
                go_on
            });
        }
    }

    /// Calls `callback(proxy, payload)` for every proxy (static or not) whose
    /// fat box the segment `origin + s · translation`, `s ∈ [0,
    /// max_fraction]`, touches, until the callback returns `false`. Movable
    /// proxies are visited first.
    pub fn ray_query<F: FnMut(u32, u32) -> bool>(
        &self,
        origin: Vec2,
        translation: Vec2,
        max_fraction: Real,
        mut callback: F,
    ) {
        let proxies = &self.proxies;
        let mut go_on = true;
        for tree in [&self.dynamic_tree, &self.static_tree] {
            if !go_on {
                break;
            }
            tree.ray_query(origin, translation, max_fraction, |_, proxy| {
                go_on = callback(proxy, proxies[proxy as usize].payload);
                go_on
            });
        }
    }

    /// Finds the new overlapping pairs: every pair of proxies whose fat boxes
    /// overlap and of which at least one moved (was created, re-inserted or
    /// touched) since the previous call; static–static pairs are never
    /// reported. Then clears the moved marks.
    ///
    /// `out` is cleared and receives the payload pairs normalised as
    /// `(min, max)`, sorted and without duplicates, so the result does not
    /// depend on insertion history. `filter(a, b)` (with `a <= b` payloads) is
    /// called once per candidate proxy pair; returning `false` drops it. Two
    /// distinct proxies with the same payload yield a pair `(p, p)`, which the
    /// filter may reject. With `team` of several threads and many proxies
    /// moved, the search runs in blocks on it; the pairs are the same for
    /// any team.
    pub fn update_pairs<F: Fn(u32, u32) -> bool + Sync>(
        &mut self,
        filter: F,
        out: &mut Vec<(u32, u32)>,
        team: &Team,
    ) {
        let bulk = self.move_buffer.len() * BULK_DIVISOR >= self.proxy_count();
        self.update_pairs_with(bulk, filter, out, team);
    }

    /// [`update_pairs`](Self::update_pairs) with the search strategy chosen
    /// by the caller: one tree query per moved proxy, or (`bulk`) one
    /// simultaneous descent of the trees, cheaper when most proxies moved.
    /// Both report the same pairs.
    fn update_pairs_with<F: Fn(u32, u32) -> bool + Sync>(
        &mut self,
        bulk: bool,
        filter: F,
        out: &mut Vec<(u32, u32)>,
        team: &Team,
    ) {
        out.clear();
        if self.static_tree.is_unbalanced() {
            // Static shapes added in an unlucky order (checked each step,
            // O(1); rebuilt rarely: a rebuilt tree is balanced).
            self.static_tree.rebuild_all(&mut self.rebuild_items);
        }
        let mut moves = std::mem::take(&mut self.move_buffer);
        moves.sort_unstable();
        moves.dedup();
        let proxies = &self.proxies;
        moves.retain(|&p| {
            let s = &proxies[p as usize];
            s.alive && s.moved
        });
        // No two proxies whose filters may pair (the trees' root bits, see
        // `dynamic_tree`'s *Filter bits*): no pair to look for (a joint
        // grid whose circles collide with nothing).
        let searched = self.dynamic_tree.may_pair_within()
            || self.dynamic_tree.may_pair_across(&self.static_tree);

        if bulk && searched {
            // The descents skip node pairs without a moved proxy below
            // either node (only pairs with a moved member are kept).
            for (is_static, marks) in [false, true].into_iter().zip(&mut self.moved_marks) {
                let tree = if is_static {
                    &self.static_tree
                } else {
                    &self.dynamic_tree
                };
                let leaves = moves
                    .iter()
                    .map(|&p| &proxies[p as usize])
                    .filter(|slot| slot.is_static == is_static)
                    .map(|slot| slot.leaf);
                tree.mark_paths(leaves, marks);
            }
        }
        let parallel = team.threads() > 1 && moves.len() >= PARALLEL_MOVES;
        if searched && parallel {
            // The filter runs on the threads; the kept pairs come back in
            // block order.
            self.find_pairs_parallel(bulk, &moves, &filter, out, team);
        } else if searched {
            let mut report = |pa: u32, pb: u32| keep_pair(&filter, out, pa, pb);
            self.find_pairs_serial(bulk, &moves, &mut report);
        }

        for &m in &moves {
            self.proxies[m as usize].moved = false;
        }
        moves.clear();
        self.move_buffer = moves;
        // Sorting packed keys is the same order as sorting the tuples.
        out.sort_unstable_by_key(|&(a, b)| (u64::from(a) << 32) | u64::from(b));
        out.dedup();
    }

    /// The candidate pairs of [`BroadPhase::update_pairs`], reported as
    /// payload pairs in any order (with duplicates).
    fn find_pairs_serial(&mut self, bulk: bool, moves: &[u32], report: &mut impl FnMut(u32, u32)) {
        let proxies = &self.proxies;
        if bulk {
            // Every overlapping pair is visited once; keep those with a
            // moved member.
            let mut visit = |x: u32, y: u32| {
                let (sx, sy) = (&proxies[x as usize], &proxies[y as usize]);
                if (sx.moved || sy.moved) && pair_overlaps(sx, sy) {
                    report(sx.payload, sy.payload);
                }
            };
            let [dynamic_marks, static_marks] = &self.moved_marks;
            let stack = &mut self.pair_stack;
            self.dynamic_tree
                .for_each_self_pair(dynamic_marks, stack, &mut visit);
            self.dynamic_tree.for_each_cross_pair(
                &self.static_tree,
                dynamic_marks,
                static_marks,
                stack,
                &mut visit,
            );
        } else {
            for &m in moves {
                let slot = proxies[m as usize];
                let fat = slot.fat;
                let mut visit = |other: u32| {
                    let o = &proxies[other as usize];
                    // When both moved, only the smaller id reports the pair.
                    if other != m && !(o.moved && other < m) && pair_overlaps(&slot, o) {
                        report(slot.payload, o.payload);
                    }
                    true
                };
                let bits = self.tree(slot.is_static).proxy_bits(slot.leaf);
                self.dynamic_tree
                    .query_proxies_filtered(&fat, bits, |_, other| visit(other));
                if !slot.is_static {
                    self.static_tree
                        .query_proxies_filtered(&fat, bits, |_, other| visit(other));
                }
            }
        }
    }

    /// [`BroadPhase::find_pairs_serial`] on the team: the moved proxies'
    /// queries (or the seeds of the bulk descent) in blocks, each block's
    /// pairs (ordered, and kept by `filter`) collected on its own, then
    /// appended to `out` in block order. The pairs are sorted afterwards,
    /// so the result is the serial one.
    fn find_pairs_parallel(
        &mut self,
        bulk: bool,
        moves: &[u32],
        filter: &(impl Fn(u32, u32) -> bool + Sync),
        out: &mut Vec<(u32, u32)>,
        team: &Team,
    ) {
        let proxies = &self.proxies;
        let (dynamic, fixed) = (&self.dynamic_tree, &self.static_tree);
        let [dynamic_marks, static_marks] = &self.moved_marks;
        let found: Vec<Vec<(u32, u32)>> = if bulk {
            let want = 64 * team.threads();
            let mut seeds = Vec::new();
            dynamic.pair_seeds(None, want, &mut seeds);
            let mut cross = Vec::new();
            dynamic.pair_seeds(Some(fixed), want, &mut cross);
            let tasks: Vec<(bool, (u32, u32))> = seeds
                .into_iter()
                .map(|s| (false, s))
                .chain(cross.into_iter().map(|s| (true, s)))
                .collect();
            const SEEDS: usize = 8;
            team.map_blocks(tasks.len().div_ceil(SEEDS), |b| {
                let block = &tasks[b * SEEDS..(b * SEEDS + SEEDS).min(tasks.len())];
                let mut pairs = Vec::new();
                let mut stack = Vec::new();
                for &(is_cross, seed) in block {
                    let other = is_cross.then_some((fixed, &static_marks[..]));
                    dynamic.for_each_pair_from(other, dynamic_marks, seed, &mut stack, |x, y| {
                        let (sx, sy) = (&proxies[x as usize], &proxies[y as usize]);
                        if (sx.moved || sy.moved) && pair_overlaps(sx, sy) {
                            keep_pair(filter, &mut pairs, sx.payload, sy.payload);
                        }
                    });
                }
                pairs
            })
        } else {
            const QUERIES: usize = PARALLEL_MOVES / 4;
            team.map_blocks(moves.len().div_ceil(QUERIES), |b| {
                let block = &moves[b * QUERIES..(b * QUERIES + QUERIES).min(moves.len())];
                let mut pairs = Vec::new();
                for &m in block {
                    let slot = proxies[m as usize];
                    let fat = slot.fat;
                    let mut visit = |other: u32| {
                        let o = &proxies[other as usize];
                        if other != m && !(o.moved && other < m) && pair_overlaps(&slot, o) {
                            keep_pair(filter, &mut pairs, slot.payload, o.payload);
                        }
                        true
                    };
                    let bits = if slot.is_static { fixed } else { dynamic }.proxy_bits(slot.leaf);
                    dynamic.query_proxies_filtered(&fat, bits, |_, other| visit(other));
                    if !slot.is_static {
                        fixed.query_proxies_filtered(&fat, bits, |_, other| visit(other));
                    }
                }
                pairs
            })
        };
        for pairs in found {
            out.extend(pairs);
        }
    }

    #[cfg(test)]
    /// Validates both trees and the proxy table; panics on inconsistency.
    pub fn validate(&self) {
        if let Err(e) = self.check() {
            panic!("{e}");
        }
    }

    /// [`validate`](Self::validate) without panicking, also on corrupt
    /// indices (a decoded snapshot): both trees, each live proxy's leaf
    /// link and fat box, the counts.
    pub fn check(&self) -> Result<(), String> {
        self.dynamic_tree
            .check()
            .map_err(|e| format!("dynamic tree: {e}"))?;
        self.static_tree
            .check()
            .map_err(|e| format!("static tree: {e}"))?;
        // The trees' margins as `with_margin` makes them (a decoded
        // snapshot's NaN margin let a new proxy's margin fail the check
        // below).
        let margin = self.dynamic_tree.margin();
        if !(margin.is_finite() && margin >= 0.0) || self.static_tree.margin() != 0.0 {
            return Err(format!(
                "tree margins {margin} and {}",
                self.static_tree.margin()
            ));
        }
        let mut live = [0usize; 2];
        for (id, s) in self.proxies.iter().enumerate() {
            if !s.alive {
                continue;
            }
            live[usize::from(s.is_static)] += 1;
            let full = self.tree(s.is_static).margin();
            if !(s.margin >= 0.0 && s.margin <= full && s.core.is_valid()) {
                return Err(format!("proxy {id}: margin {} or core box", s.margin));
            }
            match self.tree(s.is_static).leaf(s.leaf) {
                Some((user, fat)) if user as usize == id && fat == s.fat => {}
                Some(_) => return Err(format!("proxy {id}: leaf link or fat box")),
                None => return Err(format!("proxy {id}: leaf {} is not a leaf", s.leaf)),
            }
        }
        if live[0] != self.dynamic_tree.proxy_count() || live[1] != self.static_tree.proxy_count() {
            return Err("proxy counts differ from the trees'".into());
        }
        let listed = self.proxies.len().checked_sub(self.free_proxies.len());
        if listed != Some(live[0] + live[1]) {
            return Err("free list".into());
        }
        let in_range = |&p: &u32| (p as usize) < self.proxies.len();
        if !self.free_proxies.iter().all(in_range) || !self.move_buffer.iter().all(in_range) {
            return Err("a free or moved proxy id out of range".into());
        }
        let mut free = vec![false; self.proxies.len()];
        for &p in &self.free_proxies {
            if self.proxies[p as usize].alive || free[p as usize] {
                return Err(format!("free proxy {p} is live or listed twice"));
            }
            free[p as usize] = true;
        }
        Ok(())
    }

    // ---- internals ----------------------------------------------------

    #[inline]
    fn slot(&self, proxy: u32) -> ProxySlot {
        let s = self.proxies[proxy as usize];
        assert!(s.alive, "invalid proxy id {proxy}");
        s
    }

    #[inline]
    fn tree(&self, is_static: bool) -> &DynamicTree {
        if is_static {
            &self.static_tree
        } else {
            &self.dynamic_tree
        }
    }

    #[inline]
    fn tree_mut(&mut self, is_static: bool) -> &mut DynamicTree {
        if is_static {
            &mut self.static_tree
        } else {
            &mut self.dynamic_tree
        }
    }

    #[inline]
    fn mark_moved(&mut self, proxy: u32) {
        let s = &mut self.proxies[proxy as usize];
        if !s.moved {
            s.moved = true;
            self.move_buffer.push(proxy);
        }
    }
}

/// The box a shape with tight box `tight`, moving by `sweep` in a step,
/// asks its proxy's tree box to hold
/// ([`BroadPhase::move_proxy_in_batch_swept`]): swept when the move is more
/// than half the proxy's margin, else the tight box.
#[inline]
fn swept_query(slot: &ProxySlot, tight: Aabb, sweep: Vec2) -> Aabb {
    let half = 0.5 * slot.margin;
    if sweep.length_squared() > half * half {
        bounded(Aabb::new(
            tight.lower + sweep.min(Vec2::ZERO),
            tight.upper + sweep.max(Vec2::ZERO),
        ))
    } else {
        bounded(tight)
    }
}

/// Whether two proxies' boxes overlap as a pair needs: the core boxes
/// (without the velocity sweep) of two movable proxies, the tree boxes
/// otherwise (a swept box against static geometry, so that a fast shape
/// meets a wall or a one-sided chain before it arrives). The tree's
/// overlap is implied by either (every box holds its core).
#[inline]
fn pair_overlaps(a: &ProxySlot, b: &ProxySlot) -> bool {
    if a.is_static || b.is_static {
        a.fat.overlaps(&b.fat)
    } else {
        a.core.overlaps(&b.core)
    }
}

/// Appends the pair of payloads `pa`, `pb` to `out`, smaller first, when
/// `filter` keeps it (the pair search's report, serial or per block).
#[inline]
fn keep_pair(filter: &impl Fn(u32, u32) -> bool, out: &mut Vec<(u32, u32)>, pa: u32, pb: u32) {
    let (a, b) = (pa.min(pb), pa.max(pb));
    if filter(a, b) {
        out.push((a, b));
    }
}

/// A movable shape's fat-box margin as a fraction of its
/// [`extent`](janus2d_core::geometry::Shape::extent), on top of the
/// speculative distance (Box2D v3.2 sizes its margins the same way).
pub const AABB_MARGIN_FRACTION: Real = 0.125;

/// The fat-box margin of a shape's proxy, metres: the speculative distance
/// (so that pairs exist before the manifold can have points) plus
/// [`AABB_MARGIN_FRACTION`] of the shape's extent, at most `max` (the
/// broadphase's margin, [`DEFAULT_AABB_MARGIN`](crate::dynamic_tree::DEFAULT_AABB_MARGIN) by default). A box of half-width
/// 0.1 m gets 0.038 m, one of half-width 0.5 m (or anything larger) the
/// whole 0.1 m. With one margin for all, a dense pile of small shapes
/// kept a contact for every neighbour within 0.2 m (washer: 88,000
/// contacts where 23,000 touch; Box2D, sizing margins by shape, kept
/// 32,000).
#[must_use]
pub fn proxy_margin(geometry: &janus2d_core::geometry::Shape, max: Real) -> Real {
    (janus2d_core::geometry::SPECULATIVE_DISTANCE + AABB_MARGIN_FRACTION * geometry.extent())
        .min(max)
}

/// The proxy id of a shape that has none (its body is disabled):
/// [`BroadPhase::destroy_proxy`], [`BroadPhase::move_proxy`] and
/// [`BroadPhase::touch_proxy`] do nothing with it.
pub const NO_PROXY: u32 = u32::MAX;

/// Largest coordinate of a box handed to the broadphase, m: four times
/// [`MAX_COORDINATE`](janus2d_core::limits::MAX_COORDINATE), beyond any
/// shape on a body inside the world.
pub const MAX_BOX_COORDINATE: Real = 4.0 * janus2d_core::limits::MAX_COORDINATE;

/// The box handed to the broadphase: `aabb` itself when it is valid and
/// inside [`MAX_BOX_COORDINATE`] (always, while the API's limits hold),
/// otherwise clamped into it with NaN coordinates at 0, so that no
/// invalid box ever reaches a tree.
#[must_use]
pub fn bounded(aabb: Aabb) -> Aabb {
    let m = MAX_BOX_COORDINATE;
    let inside = |v: Vec2| v.x.abs() <= m && v.y.abs() <= m;
    if aabb.lower.x <= aabb.upper.x
        && aabb.lower.y <= aabb.upper.y
        && inside(aabb.lower)
        && inside(aabb.upper)
    {
        return aabb;
    }
    let fix = |x: Real| if x.is_nan() { 0.0 } else { x.clamp(-m, m) };
    let (lx, ux) = (fix(aabb.lower.x), fix(aabb.upper.x));
    let (ly, uy) = (fix(aabb.lower.y), fix(aabb.upper.y));
    Aabb::new(
        Vec2::new(lx.min(ux), ly.min(uy)),
        Vec2::new(lx.max(ux), ly.max(uy)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamic_tree::test_util::{Lcg, boxed, random_box, translate};
    use std::collections::{BTreeMap, BTreeSet};

    /// Unique payloads whose order differs from the proxy id order.
    fn payload_of(i: u32) -> u32 {
        (i * 7919) % 100_003
    }

    /// All overlapping fat-box pairs (not static–static), as payload pairs.
    fn brute_force(bp: &BroadPhase, ids: &[u32]) -> BTreeSet<(u32, u32)> {
        let boxes: Vec<Aabb> = ids.iter().map(|&p| bp.fat_aabb(p)).collect();
        let mut set = BTreeSet::new();
        for i in 0..ids.len() {
            for j in (i + 1)..ids.len() {
                if bp.is_static(ids[i]) && bp.is_static(ids[j]) {
                    continue;
                }
                if boxes[i].overlaps(&boxes[j]) {
                    let (a, b) = (bp.payload(ids[i]), bp.payload(ids[j]));
                    set.insert((a.min(b), a.max(b)));
                }
            }
        }
        set
    }

    /// Both search strategies (per-proxy queries and bulk descent) on a
    /// copy of `bp` report exactly `expected`, each pair once (payloads are
    /// unique).
    fn check_both_strategies(bp: &BroadPhase, expected: &[(u32, u32)], label: &str) {
        janus2d_core::parallel::with_team(|team| {
            check_both_strategies_on(bp, expected, label, team)
        });
    }

    fn check_both_strategies_on(
        bp: &BroadPhase,
        expected: &[(u32, u32)],
        label: &str,
        team: &Team,
    ) {
        for bulk in [false, true] {
            let mut copy = bp.clone();
            let mut pairs = Vec::new();
            let calls = std::sync::atomic::AtomicUsize::new(0);
            copy.update_pairs_with(
                bulk,
                |_, _| {
                    calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    true
                },
                &mut pairs,
                team,
            );
            assert_eq!(pairs, expected, "{label}, bulk = {bulk}");
            assert_eq!(calls.into_inner(), expected.len(), "{label}, bulk = {bulk}");
        }
    }

    /// Proxies whose filters refuse each other are not paired, and their
    /// pairs are not even offered to the caller's filter (the node pairs
    /// are skipped by their bits); both strategies report exactly the
    /// overlapping pairs whose bits may pair. A world of mutually refusing
    /// proxies offers none; one proxy given every category then pairs with
    /// every proxy it overlaps.
    #[test]
    fn refusing_filters_are_never_offered_as_pairs() {
        let mut rng = Lcg(3);
        let kinds = [
            FilterBits::of(1, u64::MAX, 0),
            FilterBits::of(2, !2, 0),
            FilterBits::of(4, 1, 0),
        ];
        let mut bp = BroadPhase::new();
        let mut bits_of = std::collections::BTreeMap::new();
        let ids: Vec<u32> = (0..2000u32)
            .map(|i| {
                let bits = kinds[rng.below(3) as usize];
                bits_of.insert(payload_of(i), bits);
                bp.create_proxy_filtered(
                    random_box(&mut rng, 100.0),
                    payload_of(i),
                    i % 10 == 0,
                    Real::INFINITY,
                    bits,
                )
            })
            .collect();
        bp.validate();
        let all = brute_force(&bp, &ids);
        let expected: Vec<(u32, u32)> = all
            .iter()
            .copied()
            .filter(|(a, b)| bits_of[a].may_pair(bits_of[b]))
            .collect();
        assert!(
            expected.len() > 300 && all.len() > expected.len() + 300,
            "{} of {}",
            expected.len(),
            all.len()
        );
        check_both_strategies(&bp, &expected, "mixed filters");

        let mut lonely = BroadPhase::new();
        let lonely_ids: Vec<u32> = (0..2000u32)
            .map(|i| {
                lonely.create_proxy_filtered(
                    random_box(&mut rng, 100.0),
                    payload_of(i),
                    i % 10 == 0,
                    Real::INFINITY,
                    kinds[1],
                )
            })
            .collect();
        assert!(brute_force(&lonely, &lonely_ids).len() > 500);
        check_both_strategies(&lonely, &[], "refusing filters");
        let mut pairs = Vec::new();
        lonely.update_pairs(|_, _| true, &mut pairs, &Team::serial());
        assert!(pairs.is_empty());
        // One of them joins every category: its pairs, and only its.
        let open = lonely_ids[1];
        lonely.set_proxy_bits(open, FilterBits::ALL);
        lonely.touch_proxy(open);
        lonely.validate();
        let mine: Vec<(u32, u32)> = brute_force(&lonely, &lonely_ids)
            .into_iter()
            .filter(|&(a, b)| a == lonely.payload(open) || b == lonely.payload(open))
            .collect();
        assert!(!mine.is_empty());
        check_both_strategies(&lonely, &mine, "one open filter");
    }

    /// 2000 random proxies, one in ten static.
    fn random_scene(rng: &mut Lcg) -> (BroadPhase, Vec<u32>) {
        let mut bp = BroadPhase::new();
        let ids = (0..2000u32)
            .map(|i| bp.create_proxy(random_box(rng, 100.0), payload_of(i), i % 10 == 0))
            .collect();
        (bp, ids)
    }

    #[test]
    fn initial_pairs_match_brute_force() {
        let mut rng = Lcg(1);
        let (mut bp, ids) = random_scene(&mut rng);
        bp.validate();
        let expected: Vec<(u32, u32)> = brute_force(&bp, &ids).into_iter().collect();
        assert!(expected.len() > 500, "scene too sparse: {}", expected.len());
        // Both search strategies (per-proxy queries and bulk descent).
        check_both_strategies(&bp, &expected, "serial");
        let mut pairs = Vec::new();
        bp.update_pairs(|_, _| true, &mut pairs, &Team::serial());
        assert_eq!(pairs, expected);
        // Nothing moved since: no new pairs.
        bp.update_pairs(|_, _| true, &mut pairs, &Team::serial());
        assert!(pairs.is_empty());
        // No static-static pair was reported.
        let statics: BTreeSet<u32> = ids
            .iter()
            .filter(|&&p| bp.is_static(p))
            .map(|&p| bp.payload(p))
            .collect();
        assert!(
            expected
                .iter()
                .all(|(a, b)| !(statics.contains(a) && statics.contains(b)))
        );
    }

    /// The pair search on the team (both strategies) reports each pair once,
    /// the same pairs as brute force, with 2 and 4 threads.
    #[cfg(feature = "parallel")]
    #[test]
    fn parallel_pair_search_matches_brute_force() {
        let mut rng = Lcg(3);
        let (bp, ids) = random_scene(&mut rng);
        let expected: Vec<(u32, u32)> = brute_force(&bp, &ids).into_iter().collect();
        for threads in [2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let label = format!("{threads} threads");
            pool.install(|| check_both_strategies(&bp, &expected, &label));
        }
    }

    #[test]
    fn moved_pairs_reported_exactly_once() {
        let mut rng = Lcg(2);
        let (mut bp, ids) = random_scene(&mut rng);
        let mut first = Vec::new();
        bp.update_pairs(|_, _| true, &mut first, &Team::serial());
        let by_payload: BTreeMap<u32, u32> = ids.iter().map(|&p| (bp.payload(p), p)).collect();

        // 500 distinct proxies: small, medium and large displacements.
        let mut order: Vec<u32> = ids.clone();
        for i in (1..order.len()).rev() {
            let j = rng.below(i as u32 + 1) as usize;
            order.swap(i, j);
        }
        let mut reinserted = BTreeSet::new();
        let mut kept = 0;
        for (k, &p) in order[..500].iter().enumerate() {
            let scale: Real = match k % 4 {
                0 | 1 => 0.08,
                2 => 1.5,
                _ => 40.0,
            };
            let d = Vec2::new(rng.range(-scale, scale), rng.range(-scale, scale));
            let tight = translate(bp.fat_aabb(p), d);
            let tight = if bp.is_static(p) {
                tight
            } else {
                tight.fattened(-bp.margin())
            };
            if bp.move_proxy(p, tight) {
                assert!(bp.is_moved(p));
                reinserted.insert(p);
            } else {
                kept += 1;
            }
        }
        assert!(
            kept > 50 && reinserted.len() > 250,
            "{kept} {}",
            reinserted.len()
        );
        bp.validate();

        // Both search strategies; each candidate pair reaches the filter once.
        let mut results = Vec::new();
        for bulk in [false, true] {
            let mut copy = bp.clone();
            let counts = std::sync::Mutex::new(BTreeMap::<(u32, u32), u32>::new());
            let mut pairs = Vec::new();
            copy.update_pairs_with(
                bulk,
                |a, b| {
                    assert!(a <= b);
                    *counts.lock().unwrap().entry((a, b)).or_default() += 1;
                    true
                },
                &mut pairs,
                &Team::serial(),
            );
            let counts = counts.into_inner().unwrap();
            assert!(counts.values().all(|&c| c == 1), "a pair was found twice");
            assert_eq!(counts.len(), pairs.len());
            results.push(pairs);
        }
        assert_eq!(results[0], results[1]);
        let mut new_pairs = Vec::new();
        bp.update_pairs(|_, _| true, &mut new_pairs, &Team::serial());
        assert_eq!(new_pairs, results[0]);

        let all = brute_force(&bp, &ids);
        let expected: Vec<(u32, u32)> = all
            .iter()
            .copied()
            .filter(|(a, b)| {
                reinserted.contains(&by_payload[a]) || reinserted.contains(&by_payload[b])
            })
            .collect();
        assert!(expected.len() > 100);
        assert_eq!(new_pairs, expected);

        // Caller-side persistence: old pairs kept while the fat boxes overlap;
        // together with the new pairs this is exactly the overlap set.
        let mut persisted: BTreeSet<(u32, u32)> = first
            .iter()
            .copied()
            .filter(|(a, b)| bp.test_overlap(by_payload[a], by_payload[b]))
            .collect();
        persisted.extend(new_pairs.iter().copied());
        assert_eq!(persisted, all);
    }

    #[test]
    fn destroy_touch_and_static_rules() {
        let mut bp = BroadPhase::new();
        let ground = bp.create_proxy(boxed(0.0, -1.0, 50.0, 1.0), 100, true);
        let wall = bp.create_proxy(boxed(-50.0, 5.0, 1.0, 6.0), 101, true);
        let a = bp.create_proxy(boxed(-49.0, 0.5, 0.5, 0.5), 7, false);
        let b = bp.create_proxy(boxed(-48.2, 0.5, 0.5, 0.5), 3, false);
        let mut pairs = Vec::new();
        bp.update_pairs(|_, _| true, &mut pairs, &Team::serial());
        // Static fat boxes are not fattened; ground and wall touch but are
        // both static.
        assert_eq!(bp.fat_aabb(ground), boxed(0.0, -1.0, 50.0, 1.0));
        assert_eq!(pairs, vec![(3, 7), (3, 100), (7, 100), (7, 101)]);

        // The filter drops pairs; a destroyed moved proxy is never reported.
        bp.touch_proxy(a);
        bp.move_proxy(b, boxed(10.0, 0.5, 0.5, 0.5));
        bp.destroy_proxy(b);
        bp.update_pairs(|x, y| (x, y) != (7, 101), &mut pairs, &Team::serial());
        assert_eq!(pairs, vec![(7, 100)]);
        assert!(!bp.is_moved(a));

        // Slot reuse: a new proxy in the freed slot is reported once.
        let c = bp.create_proxy(boxed(-49.0, 0.5, 0.5, 0.5), 9, false);
        assert_eq!(c, b);
        bp.update_pairs(|_, _| true, &mut pairs, &Team::serial());
        assert_eq!(pairs, vec![(7, 9), (9, 100), (9, 101)]);
        assert!(bp.test_overlap(a, c));
        assert!(bp.test_overlap(c, ground));
        assert!(!bp.test_overlap(wall, ground) || bp.is_static(wall));

        // Two proxies with one payload give a (p, p) pair.
        let d = bp.create_proxy(boxed(-49.0, 0.5, 0.5, 0.5), 9, false);
        bp.update_pairs(|_, _| true, &mut pairs, &Team::serial());
        assert_eq!(pairs, vec![(7, 9), (9, 9), (9, 100), (9, 101)]);
        bp.destroy_proxy(d);
        bp.validate();
        assert_eq!(bp.proxy_count(), 4);

        let mut seen = Vec::new();
        bp.query(&boxed(-49.0, 0.0, 0.1, 0.1), |_, payload| {
            seen.push(payload);
            true
        });
        seen.sort_unstable();
        assert_eq!(seen, vec![7, 9, 100, 101]);
    }

    /// Runs a scripted scene and returns every pair vector it produced.
    fn scripted_run(seed: u64) -> Vec<Vec<(u32, u32)>> {
        let mut rng = Lcg(seed);
        let mut bp = BroadPhase::with_margin(0.05);
        let mut live: Vec<u32> = Vec::new();
        let mut tights: BTreeMap<u32, Aabb> = BTreeMap::new();
        let mut outputs = Vec::new();
        let mut pairs = Vec::new();
        let mut next_payload = 0u32;
        for step in 0..40 {
            for _ in 0..50 {
                let b = random_box(&mut rng, 60.0);
                let p = bp.create_proxy(b, next_payload, rng.below(8) == 0);
                next_payload += 1;
                live.push(p);
                tights.insert(p, b);
            }
            for _ in 0..100 {
                let p = live[rng.below(live.len() as u32) as usize];
                let s = if rng.below(4) == 0 { 5.0 } else { 0.1 };
                let b = translate(tights[&p], Vec2::new(rng.range(-s, s), rng.range(-s, s)));
                bp.move_proxy(p, b);
                tights.insert(p, b);
            }
            for _ in 0..20 {
                let k = rng.below(live.len() as u32) as usize;
                let p = live.swap_remove(k);
                bp.destroy_proxy(p);
                tights.remove(&p);
            }
            bp.update_pairs(|a, b| (a + b + step) % 7 != 0, &mut pairs, &Team::serial());
            outputs.push(pairs.clone());
        }
        bp.validate();
        outputs
    }

    #[test]
    fn deterministic_and_order_independent() {
        let first = scripted_run(5);
        let second = scripted_run(5);
        assert_eq!(first.len(), 40);
        assert!(first.iter().map(Vec::len).sum::<usize>() > 1000);
        assert_eq!(first, second);
        for v in &first {
            assert!(v.windows(2).all(|w| w[0] < w[1]), "not sorted / unique");
        }

        // The same boxes inserted in reverse order give the identical pairs.
        let mut rng = Lcg(6);
        let boxes: Vec<Aabb> = (0..1500).map(|_| random_box(&mut rng, 70.0)).collect();
        let run = |reverse: bool| {
            let mut bp = BroadPhase::new();
            let mut order: Vec<usize> = (0..boxes.len()).collect();
            if reverse {
                order.reverse();
            }
            for &i in &order {
                bp.create_proxy(boxes[i], payload_of(i as u32), i % 5 == 0);
            }
            let mut pairs = Vec::new();
            bp.update_pairs(|_, _| true, &mut pairs, &Team::serial());
            pairs
        };
        let forward = run(false);
        assert!(forward.len() > 300);
        assert_eq!(forward, run(true));
    }

    #[test]
    fn small_swept_proxy_pairs_with_movable_ones_by_its_core_only() {
        let mut bp = BroadPhase::new();
        let m = 0.04;
        let a = bp.create_proxy_with_margin(boxed(0.0, 0.0, 0.1, 0.1), 1, false, m);
        let b = bp.create_proxy_with_margin(boxed(1.0, 0.0, 0.1, 0.1), 2, false, m);
        let wall = bp.create_proxy(boxed(1.5, 0.0, 0.1, 2.0), 3, true);
        let mut out = Vec::new();
        bp.update_pairs(|_, _| true, &mut out, &Team::serial());
        assert!(out.is_empty(), "{out:?}");
        // a moves 0.05 m and is swept 1.5 m to the right: its tree box now
        // covers b and the wall, its core only its own neighbourhood.
        let tight = boxed(0.05, 0.0, 0.1, 0.1);
        assert!(bp.move_proxy_in_batch_swept(a, tight, Vec2::new(1.5, 0.0)));
        bp.finish_moves();
        assert!(bp.fat_aabb(a).overlaps(&bp.fat_aabb(b)));
        bp.update_pairs(|_, _| true, &mut out, &Team::serial());
        assert_eq!(
            out,
            vec![(1, 3)],
            "the wall pairs through the sweep, b does not"
        );
        assert!(!bp.test_overlap(a, b));
        assert!(bp.test_overlap(a, wall));
        // Still inside both boxes: no move. Out of its core: a move, and a
        // pair with b once the cores meet.
        assert!(!bp.move_proxy_in_batch_swept(a, tight, Vec2::ZERO));
        let near_b = boxed(0.75, 0.0, 0.1, 0.1);
        assert!(bp.move_proxy_in_batch_swept(a, near_b, Vec2::ZERO));
        bp.finish_moves();
        bp.update_pairs(|_, _| true, &mut out, &Team::serial());
        assert_eq!(out, vec![(1, 2), (1, 3)]);
        assert!(bp.test_overlap(a, b));
        bp.validate();
    }

    /// The proxy update asks `keeps_boxes` for every shape on the team and
    /// moves only the others: where it answers true, a swept move must
    /// change nothing (no move, same boxes, no pair reported after), and
    /// where it answers false, the move must move. Small proxies (sized
    /// margins, boxes split into tree and core) and large ones, static ones
    /// and swept moves.
    #[test]
    fn keeps_boxes_is_true_exactly_when_a_swept_move_changes_nothing() {
        let mut rng = Lcg(7);
        let mut bp = BroadPhase::new();
        let mut ids = Vec::new();
        for i in 0..400u32 {
            let b = random_box(&mut rng, 40.0);
            let margin = if i % 3 == 0 { 0.1 } else { 0.03 };
            ids.push(bp.create_proxy_with_margin(b, payload_of(i), i % 10 == 0, margin));
        }
        let mut pairs = Vec::new();
        bp.update_pairs(|_, _| true, &mut pairs, &Team::serial());
        let (mut kept, mut moved) = (0, 0);
        for round in 0..20 {
            for &id in &ids {
                let step = if round % 2 == 0 { 0.02 } else { 0.2 };
                let d = Vec2::new(rng.range(-step, step), rng.range(-step, step));
                let tight = translate(bp.fat_aabb(id), d).fattened(-0.03);
                let sweep = Vec2::new(rng.range(-step, step), rng.range(-step, step));
                let before = bp.slot(id);
                let keeps = bp.keeps_boxes(id, tight, sweep);
                let did = bp.move_proxy_in_batch_swept(id, tight, sweep);
                let after = bp.slot(id);
                if keeps {
                    kept += 1;
                    assert!(!did, "round {round}, proxy {id}: kept, yet moved");
                    assert_eq!(
                        (before.fat, before.core),
                        (after.fat, after.core),
                        "round {round}, proxy {id}: kept, yet its boxes changed"
                    );
                } else {
                    moved += 1;
                    assert!(did, "round {round}, proxy {id}: not kept, yet not moved");
                }
            }
            bp.finish_moves();
            bp.update_pairs(|_, _| true, &mut pairs, &Team::serial());
            bp.validate();
        }
        assert!(
            kept > 1000 && moved > 1000,
            "both answers met: kept {kept}, moved {moved}"
        );
    }
}
