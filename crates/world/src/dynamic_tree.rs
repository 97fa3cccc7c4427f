//! The dynamic AABB tree: an incremental bounding-volume hierarchy of fat
//! boxes, the structure under the broadphase.
//!
//! # Structure
//!
//! [`DynamicTree`] is an *incremental* bounding-volume hierarchy of
//! axis-aligned boxes (the same family as Box2D's dynamic tree):
//!
//! ```text
//!                 [A]            internal node: union of its two children
//!               /     \
//!            [B]       [C]       nodes live in one Vec, addressed by u32,
//!           /   \     /   \      freed slots are chained in a free list
//!         (1)   (2) (3)   [D]
//!                        /   \   (n) leaf = one proxy: a *fat* AABB
//!                      (4)   (5)     (the tight box grown by a margin)
//!                                    and a user u32 payload
//! ```
//!
//! Each leaf stores a **fat** box: the tight box grown by a margin (default
//! [`DEFAULT_AABB_MARGIN`] = 0.1 m). As long as the tight box stays inside
//! the fat one, [`DynamicTree::move_proxy`] costs one containment test and
//! the tree is not touched; only when it leaves the fat box is the leaf
//! removed and re-inserted. The world's per-step moves go the cheaper way
//! of Box2D v3 instead: [`DynamicTree::enlarge_proxy`] gives the leaf its
//! new fat box and only grows its ancestors (marking them), and one
//! [`DynamicTree::rebuild`] after the batch rebuilds the marked part top
//! down (tumbler, 100 steps: 2,441M → 2,106M instructions for the whole
//! run; the remove/insert/rotate work was 336M of it).
//!
//! Insertion picks the sibling that minimises the total perimeter of the
//! tree (the 2D surface-area heuristic) with a branch-and-bound descent, then
//! walks back towards the root refitting boxes and applying local
//! *rotations*: a child is swapped with a grandchild when that lowers the
//! summed perimeter without making the subtree taller, or when the heights of
//! the two children differ by more than one. This keeps the tree shallow even
//! for adversarial (sorted) insertion orders: 10 000 boxes in a row give a
//! height of 15 (`log2 10 000 ≈ 13.3`).
//!
//! # What it stores
//!
//! | field / item          | what                                                              |
//! |-----------------------|-------------------------------------------------------------------|
//! | `nodes: Vec<Node>`    | leaves and internal nodes: box, parent, children, payload, height |
//! | free list             | freed slots chained through `parent`, reused first                |
//! | `root`, `proxy_count` | where every descent starts; number of leaves                      |
//! | `margin`              | tight box to fat box growth (0 for a static tree)                 |
//! | [`NULL_NODE`]         | `u32::MAX`: no parent, no child, end of the free list             |
//! | `NodeStack`           | traversal stack: 64 entries inline, heap only on overflow         |
//!
//! # Operations
//!
//! All on [`DynamicTree`]; the pair traversals are crate-internal, used by
//! `BroadPhase::update_pairs`.
//!
//! | operation                            | cost / rule                                              |
//! |--------------------------------------|----------------------------------------------------------|
//! | `create_proxy`, `destroy_proxy`      | O(log n); ids are node indices, stable until destroyed   |
//! | `move_proxy`                         | one `contains` test; re-insert only when it fails        |
//! | `enlarge_proxy`, then `rebuild`      | a batch of moves: ancestors only grow and are marked; one partial top-down rebuild of the marked nodes (as Box2D v3) |
//! | `enlarge_leaf_with_margin`, then `finish_enlarged` | the same with the ancestors' growth deferred to the batch's end; a batch that moved a quarter of the proxies or more rebuilds the whole tree from its leaves instead, its spans on a team, or (`finish_enlarged_with`, [`BulkFinish::Refit`]) refits every internal box in the tree's shape |
//! | insert / remove a leaf               | best sibling by perimeter, then refit and rotate upwards |
//! | `query`, `query_proxies`             | O(log n + k), iterative, stops when the callback says so |
//! | `ray_query`                          | the boxes a segment touches (slab test per node)         |
//! | `for_each_self_pair`, `…_cross_pair` | tree against tree: each overlapping pair once            |
//! | `create_proxy_filtered`, `set_proxy_bits` | a leaf's [`FilterBits`]; every internal node holds the union of its leaves' |
//! | `shift_origin`                       | translates every box, tree shape unchanged               |
//! | `validate`, `height`, `area_ratio`   | invariants and quality, for tests and debugging          |
//!
//! # Filter bits
//!
//! Every node also carries [`FilterBits`]: a leaf its shape's collision
//! categories and mask (in 16 bits each) and its negative group, an
//! internal node the union (bitwise or) of its children's bits and the
//! group they share (0 when they differ). No two leaves below nodes `X` and
//! `Y` can pass the filter unless `cat(X) & mask(Y) ≠ 0` and
//! `cat(Y) & mask(X) ≠ 0`, nor when every leaf below both is in one
//! negative group, so the pair descents skip such node pairs whole, and a
//! subtree whose own bits fail that test against themselves is not
//! descended into at all:
//!
//! ```text
//!   joint_grid: 10,000 circles, category 2, mask !2   → root: cat 0b10, mask …1101
//!   root × root: cat & mask = 0                        → no node pair below is visited
//!   rain: a ragdoll's 11 bodies in group −k            → a subtree of one ragdoll
//!                                                        is not descended into
//! ```
//!
//! Categories 0–14 keep their own bits; bit 15 stands for all of 15–63
//! (set when any of them is). A common bit of two full 64-bit filters is
//! then a common bit of their 16-bit forms, so the test never skips a pair
//! the full filter would let through; a shape in a positive group (which
//! collides with its group whatever the masks) takes [`FilterBits::ALL`]
//! and never prunes.

use janus2d_core::geometry::Aabb;
use janus2d_core::math::{Real, Vec2};
use janus2d_core::parallel::Team;

/// The "no node" index (`u32::MAX`), used for absent parents and children.
pub const NULL_NODE: u32 = u32::MAX;

/// Levels a tree may grow above a balanced one (`⌈log₂ n⌉`) before
/// [`DynamicTree::is_unbalanced`] says so: the insertion heuristics keep
/// random inserts within a few levels; a static ground inserted box by box
/// along a row went 12 levels over (height 24 for 2,505 boxes, rain).
pub const SLACK_LEVELS: u32 = 6;

/// Default fat-box margin, in metres (0.1 m): how far a shape may move
/// before its proxy is re-inserted into the tree.
pub const DEFAULT_AABB_MARGIN: Real = 0.1;

/// A batch of deferred moves ([`DynamicTree::enlarge_leaf_with_margin`])
/// that enlarged at least one proxy in this many rebuilds the whole tree
/// from its leaves ([`DynamicTree::finish_enlarged`]) rather than growing
/// each leaf's ancestors and rebuilding the grown part. In scenes where
/// most shapes are in flight (smash, washer, spinner, rain, joint_grid:
/// 50–94% of the proxies move each step) the ancestors' walks cost as
/// much as the rebuild and leave nearly every internal node to rebuild.
pub const FULL_REBUILD_DIVISOR: usize = 4;

/// A step whose many proxy moves (a quarter of the movable proxies or
/// more) rebuild the whole tree comes once in this many; the others refit
/// the tree in its shape ([`BulkFinish`]; the world chooses at the end of
/// its step). A refit costs about a third of a rebuild, and the shape a
/// rebuild gave stays good for a few steps of motion. `perf` samples of
/// janus2d alone, one thread, the tree's rebuild or refit, the marks and
/// the pair search together, every step rebuilt → one in eight: rain 6,471 → 3,489, joint_grid 1,415 → 448,
/// spinner 6,744 → 6,098, washer 7,656 → 6,550, tumbler 2,553 → 2,195,
/// smash 2,781 → 2,259 (the pair search itself within 3%). A period, not
/// a measure of the tree's looseness, so that the choice depends on the
/// step count alone: a world restored from a snapshot makes the same
/// choices, and its tree stays the original's. (Refitting while the
/// internal boxes' summed perimeter stayed within 5, 10 or 20% of the last
/// rebuild's gave about the same figures, but that bound is not in a
/// snapshot.)
pub const TREE_REBUILD_PERIOD: u64 = 8;

/// What a bulk batch of moves ([`DynamicTree::pending_is_bulk`]) does
/// to the tree in [`DynamicTree::finish_enlarged_with`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BulkFinish {
    /// Rebuild the whole tree from its leaves (the tightest tree, the
    /// pair search's fastest; costs a sort-like pass over the leaves).
    Rebuild,
    /// Keep the tree's shape and refit every internal box (one pass,
    /// about a third of a rebuild; the tree loosens as its leaves drift
    /// apart, so the caller rebuilds now and then).
    Refit,
}

/// The whole-tree rebuild splits the top of the tree on the caller down to
/// spans of at most `1/TOP_SPLIT_SHARE` of the leaves (and at least
/// [`MIN_SPAN`]); each span below is built as a block of the team.
const TOP_SPLIT_SHARE: usize = 8;

/// Smallest span of leaves the whole-tree rebuild hands to a block.
const MIN_SPAN: usize = 256;

/// Inline capacity of the traversal stack. A depth-first traversal needs at
/// most `height + 1` entries, so the heap fallback is never used by trees of
/// sane height (10⁶ proxies give a height near 25).
const STACK_INLINE: usize = 64;

/// Depth-first traversal stack: a fixed array on the call stack with a heap
/// fallback that only allocates if it overflows (never in practice).
/// The two children of internal node `n` of `nodes`, each with its node.
#[inline(always)]
fn children_of<'n>(nodes: &'n [Node], n: &Node) -> [(u32, &'n Node); 2] {
    let (c1, c2) = (n.child1, n.child2);
    [(c1, &nodes[c1 as usize]), (c2, &nodes[c2 as usize])]
}

/// Pushes the pairs (`pair(c)`) of a split node's `children` with the
/// other node that pass `test`, both tested before either is pushed (their
/// loads overlap), the second child first so that the first pops first.
#[inline(always)]
fn push_passing(
    stack: &mut Vec<(u32, u32)>,
    [(c1, n1), (c2, n2)]: [(u32, &Node); 2],
    test: impl Fn(&Node, u32) -> bool,
    pair: impl Fn(u32) -> (u32, u32),
) {
    let (keep1, keep2) = (test(n1, c1), test(n2, c2));
    if keep2 {
        stack.push(pair(c2));
    }
    if keep1 {
        stack.push(pair(c1));
    }
}

/// Whether node `n` is marked ([`DynamicTree::mark_paths`]); every node is
/// when there are no marks.
#[inline(always)]
fn marked(marks: &[bool], n: u32) -> bool {
    marks.get(n as usize).copied().unwrap_or(true)
}

struct NodeStack {
    inline: [u32; STACK_INLINE],
    len: usize,
    spill: Vec<u32>,
}

impl NodeStack {
    #[inline(always)]
    fn new(first: u32) -> Self {
        let mut inline = [NULL_NODE; STACK_INLINE];
        inline[0] = first;
        NodeStack {
            inline,
            len: 1,
            spill: Vec::new(),
        }
    }

    #[inline(always)]
    fn push(&mut self, index: u32) {
        if self.len < STACK_INLINE {
            self.inline[self.len] = index;
            self.len += 1;
        } else {
            self.spill.push(index);
        }
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<u32> {
        if let Some(index) = self.spill.pop() {
            Some(index)
        } else if self.len > 0 {
            self.len -= 1;
            Some(self.inline[self.len])
        } else {
            None
        }
    }
}

/// A node's collision filter in 16 bits for the pair descents (see the
/// module docs, *Filter bits*): the categories a leaf belongs to and the
/// categories it collides with, or their unions over an internal node's
/// leaves. Categories 0–14 keep their bits; bit 15 stands for 15–63. A
/// negative group shared by every leaf below refuses all of their pairs.
///
/// ```
/// use janus2d_world::dynamic_tree::FilterBits;
/// let grid = FilterBits::of(2, !2, 0);
/// assert!(!grid.may_pair(grid)); // the grid's circles never meet
/// assert!(grid.may_pair(FilterBits::of(1, u64::MAX, 0)));
/// // Categories 15–63 share bit 15: a common one is never lost.
/// assert!(FilterBits::of(1 << 40, 1 << 40, 0).may_pair(FilterBits::of(1 << 40, 1 << 40, 0)));
/// // A positive group collides whatever the masks: it never prunes.
/// assert!(FilterBits::of(2, !2, 3).may_pair(FilterBits::of(2, !2, 3)));
/// // One negative group never collides; two different ones may.
/// let (limb, other) = (FilterBits::of(2, 3, -4), FilterBits::of(2, 3, -5));
/// assert!(!limb.may_pair(limb));
/// assert!(limb.may_pair(other) && !limb.union(limb).may_pair(limb));
/// assert!(limb.union(other).may_pair(limb));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FilterBits {
    /// Categories: bits 0–14 as they are, bit 15 for any of 15–63.
    pub category: u16,
    /// Categories collided with, in the same 16 bits.
    pub mask: u16,
    /// The negative group every leaf below shares (0: none, or mixed):
    /// shapes of one negative group never collide.
    pub group: i32,
}

impl Default for FilterBits {
    fn default() -> Self {
        Self::ALL
    }
}

impl FilterBits {
    /// Pairs with anything (a proxy created without a filter).
    pub const ALL: FilterBits = FilterBits {
        category: u16::MAX,
        mask: u16::MAX,
        group: 0,
    };

    /// The bits of a shape's filter: `category_bits`, `mask_bits` and
    /// `group_index` as in [`Filter`](crate::Filter). A positive group
    /// overrides the masks, so it gives [`FilterBits::ALL`].
    #[must_use]
    pub fn of(category_bits: u64, mask_bits: u64, group_index: i32) -> Self {
        if group_index > 0 {
            return Self::ALL;
        }
        const LOW: u64 = (1 << 15) - 1;
        let fold = |x: u64| (x & LOW) as u16 | (u16::from(x > LOW) << 15);
        FilterBits {
            category: fold(category_bits),
            mask: fold(mask_bits),
            group: group_index,
        }
    }

    /// Whether a leaf below `self` and one below `other` may pass each
    /// other's filter (false: no pair of them can: their categories and
    /// masks miss, or all of them share one negative group).
    #[inline(always)]
    #[must_use]
    pub fn may_pair(self, other: FilterBits) -> bool {
        (self.group == 0 || self.group != other.group)
            && self.category & other.mask != 0
            && other.category & self.mask != 0
    }

    /// The bits of a node over both sets of leaves (the group kept only
    /// when both share it).
    #[inline(always)]
    #[must_use]
    pub fn union(self, other: FilterBits) -> FilterBits {
        FilterBits {
            category: self.category | other.category,
            mask: self.mask | other.mask,
            group: if self.group == other.group {
                self.group
            } else {
                0
            },
        }
    }
}

/// One node of the tree: a leaf (a proxy) or an internal node.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Node {
    /// Fat box of a leaf, or the union of the children of an internal node.
    aabb: Aabb,
    /// Parent index, or the next free node while on the free list.
    parent: u32,
    /// First child, [`NULL_NODE`] for a leaf.
    child1: u32,
    /// Second child, [`NULL_NODE`] for a leaf.
    child2: u32,
    /// Payload of a leaf.
    user_data: u32,
    /// 0 for a leaf, `1 + max(child heights)` otherwise.
    height: u16,
    /// A leaf's filter, or the union of the children's (see
    /// [`FilterBits`]). Not in snapshots' bytes: a decoded tree starts
    /// with [`FilterBits::ALL`] everywhere (consistent, prunes nothing)
    /// and the world sets each proxy's bits from its shape's filter again.
    #[cfg_attr(feature = "serde", serde(skip))]
    bits: FilterBits,
    /// False while on the free list.
    allocated: bool,
    /// An internal node whose box [`DynamicTree::enlarge_proxy`] grew (or
    /// an ancestor of one): rebuilt by [`DynamicTree::rebuild`]. Always
    /// false outside that window.
    #[cfg_attr(feature = "serde", serde(skip))]
    enlarged: bool,
}

impl Node {
    const EMPTY: Node = Node {
        aabb: Aabb {
            lower: Vec2::ZERO,
            upper: Vec2::ZERO,
        },
        parent: NULL_NODE,
        child1: NULL_NODE,
        child2: NULL_NODE,
        user_data: 0,
        height: 0,
        bits: FilterBits::ALL,
        allocated: false,
        enlarged: false,
    };

    #[inline(always)]
    fn is_leaf(&self) -> bool {
        self.child1 == NULL_NODE
    }
}

/// The local restructurings tried by [`DynamicTree::rotate`]. With node `A`
/// having children `B = {D, E}` and `C = {F, G}`, `XY` swaps `X` and `Y`.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Rotation {
    None,
    BF,
    BG,
    CD,
    CE,
    DF,
    DG,
}

/// An incremental AABB tree (bounding-volume hierarchy) of fat boxes.
///
/// Proxy ids are node indices; they stay valid until
/// [`destroy_proxy`](Self::destroy_proxy), across any number of
/// [`move_proxy`](Self::move_proxy) calls. All operations are deterministic:
/// the same sequence of calls builds the same tree.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct DynamicTree {
    nodes: Vec<Node>,
    root: u32,
    free_list: u32,
    proxy_count: u32,
    margin: Real,
    /// Leaves given new boxes by [`DynamicTree::enlarge_leaf_with_margin`]
    /// whose ancestors wait for [`DynamicTree::finish_enlarged`]. Empty
    /// between batches (so never in a snapshot).
    #[cfg_attr(feature = "serde", serde(skip))]
    pending: Vec<u32>,
    /// The internal nodes in an order that puts children before parents,
    /// for [`DynamicTree::refit_all`]; valid while `refit_order_ready`.
    /// Derived from the links, so not in a snapshot.
    #[cfg_attr(feature = "serde", serde(skip))]
    refit_order: Vec<u32>,
    /// Whether `refit_order` lists the internal nodes of the tree as it
    /// is. Every change to a link clears it; a whole rebuild sets it with
    /// its internal slots in ascending order (each span's root after its
    /// children's), and the first refit after any other change sets it
    /// from a walk of the tree.
    #[cfg_attr(feature = "serde", serde(skip))]
    refit_order_ready: bool,
}

impl Default for DynamicTree {
    fn default() -> Self {
        Self::new()
    }
}

impl DynamicTree {
    /// An empty tree with the default margin [`DEFAULT_AABB_MARGIN`] (0.1 m).
    pub fn new() -> Self {
        Self::with_margin(DEFAULT_AABB_MARGIN)
    }

    /// An empty tree whose fat boxes are the tight boxes grown by `margin`
    /// metres on every side (`margin >= 0`; 0 for proxies that never move).
    pub fn with_margin(margin: Real) -> Self {
        assert!(
            margin >= 0.0 && margin.is_finite(),
            "fat-box margin must be finite and non-negative"
        );
        DynamicTree {
            nodes: Vec::new(),
            root: NULL_NODE,
            free_list: NULL_NODE,
            proxy_count: 0,
            margin,
            pending: Vec::new(),
            refit_order: Vec::new(),
            refit_order_ready: false,
        }
    }

    /// The fat-box margin in metres.
    #[inline]
    pub fn margin(&self) -> Real {
        self.margin
    }

    /// Number of proxies (leaves) in the tree.
    #[inline]
    pub fn proxy_count(&self) -> usize {
        self.proxy_count as usize
    }

    /// True when the tree holds no proxy.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.root == NULL_NODE
    }

    /// The box enclosing every proxy, `None` when the tree is empty.
    pub fn root_aabb(&self) -> Option<Aabb> {
        (self.root != NULL_NODE).then(|| self.nodes[self.root as usize].aabb)
    }

    /// Height of the tree: 0 when empty or with a single proxy, otherwise the
    /// number of edges on the longest root-to-leaf path.
    pub fn height(&self) -> u32 {
        if self.root == NULL_NODE {
            0
        } else {
            u32::from(self.nodes[self.root as usize].height)
        }
    }

    /// Sum of the perimeters of the internal nodes divided by the perimeter of
    /// the root (a quality measure: lower is better; 0 for fewer than 2
    /// proxies).
    pub fn area_ratio(&self) -> Real {
        if self.root == NULL_NODE {
            return 0.0;
        }
        let root_perimeter = self.nodes[self.root as usize].aabb.perimeter();
        if root_perimeter <= 0.0 {
            return 0.0;
        }
        let total: Real = self
            .nodes
            .iter()
            .filter(|n| n.allocated && !n.is_leaf())
            .map(|n| n.aabb.perimeter())
            .sum();
        total / root_perimeter
    }

    /// Inserts a proxy for the tight box `aabb` (stored fattened by the
    /// margin) carrying `user_data`, and returns its id.
    pub fn create_proxy(&mut self, aabb: Aabb, user_data: u32) -> u32 {
        self.create_proxy_with_margin(aabb, user_data, self.margin)
    }

    /// [`create_proxy`](Self::create_proxy) with a margin of the proxy's
    /// own (metres, `≥ 0`) instead of the tree's.
    pub fn create_proxy_with_margin(&mut self, aabb: Aabb, user_data: u32, margin: Real) -> u32 {
        self.create_proxy_filtered(aabb, user_data, margin, FilterBits::ALL)
    }

    /// [`create_proxy_with_margin`](Self::create_proxy_with_margin) for a
    /// shape with filter bits `bits`: the pair descents skip it where the
    /// bits say it pairs with nothing there.
    pub fn create_proxy_filtered(
        &mut self,
        aabb: Aabb,
        user_data: u32,
        margin: Real,
        bits: FilterBits,
    ) -> u32 {
        debug_assert!(aabb.is_valid(), "invalid AABB {aabb:?}");
        let id = self.allocate_node();
        {
            let node = &mut self.nodes[id as usize];
            node.aabb = aabb.fattened(margin);
            node.user_data = user_data;
            node.height = 0;
            node.bits = bits;
        }
        self.insert_leaf(id);
        self.proxy_count += 1;
        id
    }

    /// Gives proxy `id` new filter bits (its shape's filter changed) and
    /// recomputes its ancestors' unions.
    pub fn set_proxy_bits(&mut self, id: u32, bits: FilterBits) {
        self.check_proxy(id);
        self.nodes[id as usize].bits = bits;
        let mut index = self.nodes[id as usize].parent;
        while index != NULL_NODE {
            let n = self.nodes[index as usize];
            let union = self.nodes[n.child1 as usize]
                .bits
                .union(self.nodes[n.child2 as usize].bits);
            if union == n.bits {
                break;
            }
            self.nodes[index as usize].bits = union;
            index = n.parent;
        }
    }

    /// The filter bits of proxy `id`.
    #[inline]
    #[must_use]
    pub fn proxy_bits(&self, id: u32) -> FilterBits {
        self.check_proxy(id);
        self.nodes[id as usize].bits
    }

    /// Whether two proxies of this tree may pass each other's category test
    /// (the root's bits against themselves; false for fewer than two).
    #[must_use]
    pub fn may_pair_within(&self) -> bool {
        self.root != NULL_NODE && {
            let root = &self.nodes[self.root as usize];
            !root.is_leaf() && root.bits.may_pair(root.bits)
        }
    }

    /// Whether a proxy of this tree and one of `other` may pass each
    /// other's category test (the roots' bits).
    #[must_use]
    pub fn may_pair_across(&self, other: &DynamicTree) -> bool {
        self.root != NULL_NODE
            && other.root != NULL_NODE
            && self.nodes[self.root as usize]
                .bits
                .may_pair(other.nodes[other.root as usize].bits)
    }

    /// Removes a proxy; its id may be reused by a later
    /// [`create_proxy`](Self::create_proxy).
    pub fn destroy_proxy(&mut self, id: u32) {
        self.check_proxy(id);
        self.remove_leaf(id);
        self.free_node(id);
        self.proxy_count -= 1;
    }

    /// Updates a proxy with its new tight box. Returns `true` when the proxy
    /// was re-inserted (the tight box left the fat box; the new fat box is the
    /// tight box grown by the margin), `false` when nothing changed.
    pub fn move_proxy(&mut self, id: u32, aabb: Aabb) -> bool {
        self.move_proxy_with_margin(id, aabb, self.margin)
    }

    /// [`move_proxy`](Self::move_proxy) with the proxy's own margin (as
    /// given to [`create_proxy_with_margin`](Self::create_proxy_with_margin)).
    pub fn move_proxy_with_margin(&mut self, id: u32, aabb: Aabb, margin: Real) -> bool {
        self.check_proxy(id);
        debug_assert!(aabb.is_valid(), "invalid AABB {aabb:?}");
        if self.nodes[id as usize].aabb.contains(&aabb) {
            return false;
        }
        self.remove_leaf(id);
        self.nodes[id as usize].aabb = aabb.fattened(margin);
        self.insert_leaf(id);
        true
    }

    /// [`move_proxy`](Self::move_proxy) without restructuring the tree:
    /// when the tight box left the fat box, the leaf takes the new fat box
    /// and its ancestors only grow to cover it, each marked as enlarged.
    /// Queries stay correct (every box still covers its subtree); call
    /// [`rebuild`](Self::rebuild) once after a batch of moves to restore
    /// tight boxes and a good shape. Box2D v3 moves its dynamic proxies
    /// this way: many moves then cost one partial rebuild instead of a
    /// removal, an insertion and the rotations of each.
    pub fn enlarge_proxy(&mut self, id: u32, aabb: Aabb) -> bool {
        self.enlarge_proxy_with_margin(id, aabb, self.margin)
    }

    /// [`enlarge_proxy`](Self::enlarge_proxy) with the proxy's own margin
    /// (as given to [`create_proxy_with_margin`](Self::create_proxy_with_margin)).
    pub fn enlarge_proxy_with_margin(&mut self, id: u32, aabb: Aabb, margin: Real) -> bool {
        let moved = self.set_leaf_box(id, aabb, margin);
        if moved {
            self.grow_ancestors(id);
        }
        moved
    }

    /// [`enlarge_proxy_with_margin`](Self::enlarge_proxy_with_margin) with
    /// the ancestors left for later: the leaf takes its new fat box now and
    /// is listed, and [`finish_enlarged`](Self::finish_enlarged), which
    /// must end the batch before any query or other change, grows the
    /// ancestors of every listed leaf (or rebuilds the whole tree when
    /// many were listed). Returns whether the leaf moved.
    pub fn enlarge_leaf_with_margin(&mut self, id: u32, aabb: Aabb, margin: Real) -> bool {
        let moved = self.set_leaf_box(id, aabb, margin);
        if moved {
            self.pending.push(id);
        }
        moved
    }

    /// Gives leaf `id` the fat box of `aabb` when `aabb` left its box;
    /// returns whether it did. The ancestors are left as they were.
    fn set_leaf_box(&mut self, id: u32, aabb: Aabb, margin: Real) -> bool {
        self.check_proxy(id);
        debug_assert!(aabb.is_valid(), "invalid AABB {aabb:?}");
        if self.nodes[id as usize].aabb.contains(&aabb) {
            return false;
        }
        self.nodes[id as usize].aabb = aabb.fattened(margin);
        true
    }

    /// Whether the batch of [`enlarge_leaf_with_margin`](Self::enlarge_leaf_with_margin)
    /// calls so far moved at least one proxy in [`FULL_REBUILD_DIVISOR`],
    /// so that [`finish_enlarged`](Self::finish_enlarged) will rebuild the
    /// whole tree.
    #[must_use]
    pub fn pending_is_bulk(&self) -> bool {
        !self.pending.is_empty()
            && self.pending.len() * FULL_REBUILD_DIVISOR >= self.proxy_count as usize
    }

    /// Ends a batch of [`enlarge_leaf_with_margin`](Self::enlarge_leaf_with_margin):
    /// for a bulk batch ([`pending_is_bulk`](Self::pending_is_bulk)) the
    /// whole tree is rebuilt from its leaves, its top on the caller and the
    /// spans below as blocks of `team`; otherwise each listed leaf's
    /// ancestors grow to cover it, in the order listed (exactly as
    /// [`enlarge_proxy_with_margin`](Self::enlarge_proxy_with_margin) at
    /// the time of the move), and [`rebuild`](Self::rebuild) rebuilds the
    /// grown part. The tree comes out the same for any team.
    pub fn finish_enlarged(&mut self, items: &mut Vec<(Vec2, u32)>, team: &Team) {
        self.finish_enlarged_with(items, team, BulkFinish::Rebuild);
    }

    /// [`finish_enlarged`](Self::finish_enlarged), a bulk batch finished as
    /// `bulk` says (a refit keeps the tree's shape; a batch of few moves
    /// is finished as always).
    pub fn finish_enlarged_with(
        &mut self,
        items: &mut Vec<(Vec2, u32)>,
        team: &Team,
        bulk_finish: BulkFinish,
    ) {
        if self.pending.is_empty() {
            return;
        }
        let bulk = self.pending_is_bulk();
        let mut pending = std::mem::take(&mut self.pending);
        if bulk {
            match bulk_finish {
                BulkFinish::Rebuild => self.rebuild_from_leaves(items, team),
                BulkFinish::Refit => self.refit_all(),
            }
        } else {
            for &id in &pending {
                self.grow_ancestors(id);
            }
            self.rebuild(items);
        }
        pending.clear();
        self.pending = pending;
    }

    /// Recomputes every internal node from its children (boxes, heights,
    /// filter bits), children before parents: every box again exactly the
    /// union of its children's, the shape kept.
    ///
    /// The order is kept from one refit to the next while no link
    /// changes: after a whole rebuild it is the internal slots ascending
    /// (read from memory in order), otherwise a walk from the root
    /// reversed, made once. Any order with children first gives the same
    /// boxes.
    fn refit_all(&mut self) {
        if self.root == NULL_NODE {
            return;
        }
        let mut order = std::mem::take(&mut self.refit_order);
        if !self.refit_order_ready {
            order.clear();
            let mut stack = NodeStack::new(self.root);
            while let Some(index) = stack.pop() {
                let node = &self.nodes[index as usize];
                if node.is_leaf() {
                    continue;
                }
                order.push(index);
                stack.push(node.child1);
                stack.push(node.child2);
            }
            order.reverse();
        }
        for &index in &order {
            self.refit(index);
        }
        self.refit_order = order;
        self.refit_order_ready = true;
    }

    /// Grows the ancestors of leaf `id` to cover its box, marking them.
    fn grow_ancestors(&mut self, id: u32) {
        let fat = self.nodes[id as usize].aabb;
        let mut index = self.nodes[id as usize].parent;
        // Grow the ancestors until one already covers the new box…
        while index != NULL_NODE {
            let node = &mut self.nodes[index as usize];
            let grows = !node.aabb.contains(&fat);
            if grows {
                node.aabb = node.aabb.union(&fat);
            }
            node.enlarged = true;
            index = node.parent;
            if !grows {
                break;
            }
        }
        // …and mark the rest of the path, up to a marked node, so that the
        // rebuild reaches every enlarged node from the root.
        while index != NULL_NODE && !self.nodes[index as usize].enlarged {
            self.nodes[index as usize].enlarged = true;
            index = self.nodes[index as usize].parent;
        }
    }

    /// Rebuilds the whole tree from its leaves, top down, each node split
    /// as [`rebuild`](Self::rebuild) splits (at the middle of its leaves'
    /// centres along the longer axis). The leaves are taken in node order
    /// and the internal nodes keep their slots: a span of `k` leaves owns
    /// `k − 1` consecutive internal slots (in node order), the first part
    /// of them its first child's, then its second child's, then its own
    /// root, so every span's nodes are known before it is built. The top
    /// spans are split here; those of at most `n / TOP_SPLIT_SHARE` leaves
    /// are built as blocks of `team`, then written in block order and the
    /// top refitted. The scan for the leaves and the internal slots runs
    /// in blocks of nodes on the team too. The result depends on the
    /// leaves alone, not on the team.
    ///
    /// ```text
    /// team:    scan: leaves, internal slots ┐              ┌─ spans ─┐
    /// caller:                               └─ top splits ─┘         └─ write, refit top
    /// ```
    fn rebuild_from_leaves(&mut self, items: &mut Vec<(Vec2, u32)>, team: &Team) {
        items.clear();
        // The internal slots in node order: the next refits' order, kept
        // below.
        let mut slots = std::mem::take(&mut self.refit_order);
        slots.clear();
        self.refit_order_ready = false;
        let nodes = &self.nodes[..];
        if team.threads() == 1 || nodes.len() < 2 * SCAN_BLOCK {
            scan_nodes(nodes, 0, items, &mut slots);
        } else {
            // The scan reads every node: in blocks on the team (rain at
            // two threads: two fifths of the leader's rebuild), joined in
            // block order, so the lists are the serial scan's.
            let blocks = nodes.len().div_ceil(SCAN_BLOCK);
            let parts = team.map_blocks(blocks, |b| {
                let start = b * SCAN_BLOCK;
                let end = (start + SCAN_BLOCK).min(nodes.len());
                let (mut leaves, mut inner) = (Vec::new(), Vec::new());
                scan_nodes(&nodes[start..end], start, &mut leaves, &mut inner);
                (leaves, inner)
            });
            for (leaves, inner) in parts {
                items.extend_from_slice(&leaves);
                slots.extend_from_slice(&inner);
            }
        }
        let n = items.len();
        if n == 0 {
            self.refit_order = slots;
            return;
        }
        debug_assert_eq!(slots.len() + 1, n, "a full tree has n - 1 internal nodes");
        let cut = (n / TOP_SPLIT_SHARE).max(MIN_SPAN);
        let mut top = Vec::new();
        let mut spans = Vec::new();
        let mut work = vec![Span {
            start: 0,
            end: n,
            slot: 0,
            parent: NULL_NODE,
            first: true,
        }];
        while let Some(span) = work.pop() {
            if span.len() <= cut {
                spans.push(span);
                continue;
            }
            let split = span.start + partition_mid(&mut items[span.start..span.end]);
            let id = slots[span.root_slot()];
            self.nodes[id as usize] = Node {
                allocated: true,
                ..Node::EMPTY
            };
            self.place(id, span.parent, span.first);
            top.push(id);
            let [first, second] = span.halves(split, id);
            work.push(second);
            work.push(first);
        }
        let built = {
            let (nodes, items, slots) = (&self.nodes, &items[..], &slots[..]);
            team.map_blocks(spans.len(), |k| build_span(nodes, items, slots, spans[k]))
        };
        for (span, built) in spans.iter().zip(built) {
            for (id, node) in built.made {
                self.nodes[id as usize] = node;
            }
            for (leaf, parent) in built.leaves {
                self.nodes[leaf as usize].parent = parent;
            }
            self.place(built.root, span.parent, span.first);
        }
        // The top nodes were made parents first: refit in reverse.
        for &id in top.iter().rev() {
            self.refit(id);
        }
        // Each span's root slot follows its children's: ascending, the
        // internal slots put children first (the refits' order until a
        // link changes).
        self.refit_order = slots;
        self.refit_order_ready = true;
    }

    /// Hangs `id` under `parent` as its first or second child (or makes it
    /// the root when `parent` is [`NULL_NODE`]).
    fn place(&mut self, id: u32, parent: u32, first: bool) {
        self.refit_order_ready = false;
        self.nodes[id as usize].parent = parent;
        if parent == NULL_NODE {
            self.root = id;
        } else if first {
            self.nodes[parent as usize].child1 = id;
        } else {
            self.nodes[parent as usize].child2 = id;
        }
    }

    /// Rebuilds the part of the tree above the leaves moved by
    /// [`enlarge_proxy`](Self::enlarge_proxy): the enlarged internal nodes
    /// are freed, and the leaves and untouched subtrees below them are
    /// joined again top down, each node split at the middle of its items'
    /// centres along the longer axis (half by count when that leaves a side
    /// empty). Afterwards every internal box is again exactly the union of
    /// its children. Costs nothing when nothing was enlarged.
    pub fn rebuild(&mut self, items: &mut Vec<(Vec2, u32)>) {
        items.clear();
        if self.root == NULL_NODE || !self.nodes[self.root as usize].enlarged {
            return;
        }
        // The items: leaves and untouched subtrees under enlarged nodes.
        self.rejoin(items, false);
    }

    /// Rebuilds the whole tree top down as [`rebuild`](Self::rebuild) does
    /// the enlarged part: every internal node is freed and the leaves are
    /// joined again, each node split at the middle of its leaves' centres
    /// along the longer axis. Proxy ids (the leaves) do not change. For a
    /// tree grown one insertion at a time in an unlucky order (a static
    /// ground of boxes inserted row by row grows tall and overlapping).
    pub fn rebuild_all(&mut self, items: &mut Vec<(Vec2, u32)>) {
        items.clear();
        if self.root == NULL_NODE {
            return;
        }
        self.rejoin(items, true);
    }

    /// Frees the internal nodes from the root down to the items (the
    /// leaves, and with `whole` false the subtrees not enlarged), collects
    /// the items with their boxes' centres and joins them again top down
    /// under a new root.
    fn rejoin(&mut self, items: &mut Vec<(Vec2, u32)>, whole: bool) {
        self.refit_order_ready = false;
        let mut stack = NodeStack::new(self.root);
        while let Some(index) = stack.pop() {
            let node = self.nodes[index as usize];
            if node.is_leaf() || !(whole || node.enlarged) {
                items.push((centre_of(&node.aabb), index));
            } else {
                stack.push(node.child2);
                stack.push(node.child1);
                self.free_node(index);
            }
        }
        self.root = self.build_top_down(items);
        self.nodes[self.root as usize].parent = NULL_NODE;
    }

    /// Whether the tree is taller than a balanced one by more than
    /// [`SLACK_LEVELS`] levels (see [`rebuild_all`](Self::rebuild_all)).
    #[must_use]
    pub fn is_unbalanced(&self) -> bool {
        let n = self.proxy_count();
        let balanced = usize::BITS - n.leading_zeros();
        self.height() > balanced + SLACK_LEVELS
    }

    /// Joins `items` (roots of subtrees, each with its box's centre) under
    /// new internal nodes, top down and without recursion; returns the new
    /// root. The centres travel with the ids, so each split reads one
    /// contiguous array rather than every item's node.
    fn build_top_down(&mut self, items: &mut [(Vec2, u32)]) -> u32 {
        self.refit_order_ready = false;
        if items.len() == 1 {
            return items[0].1;
        }
        // (range of items, parent, as child1) still to build.
        let mut work: Vec<(usize, usize, u32, bool)> = vec![(0, items.len(), NULL_NODE, true)];
        let mut made: Vec<u32> = Vec::with_capacity(items.len());
        let mut root = NULL_NODE;
        while let Some((start, end, parent, first)) = work.pop() {
            let node = if end - start == 1 {
                items[start].1
            } else {
                let split = start + partition_mid(&mut items[start..end]);
                let node = self.allocate_node();
                made.push(node);
                work.push((split, end, node, false));
                work.push((start, split, node, true));
                node
            };
            self.nodes[node as usize].parent = parent;
            if parent == NULL_NODE {
                root = node;
            } else if first {
                self.nodes[parent as usize].child1 = node;
            } else {
                self.nodes[parent as usize].child2 = node;
            }
        }
        // Children were made after their parents: refit in reverse.
        for &node in made.iter().rev() {
            self.refit(node);
        }
        root
    }

    /// The fat box of a proxy.
    #[inline]
    pub fn fat_aabb(&self, id: u32) -> Aabb {
        self.check_proxy(id);
        self.nodes[id as usize].aabb
    }

    /// The payload of a proxy.
    #[inline]
    pub fn user_data(&self, id: u32) -> u32 {
        self.check_proxy(id);
        self.nodes[id as usize].user_data
    }

    /// The payload and fat box of leaf `id`, or `None` when `id` is not an
    /// allocated leaf (never panics; for checks).
    #[must_use]
    pub fn leaf(&self, id: u32) -> Option<(u32, Aabb)> {
        self.nodes
            .get(id as usize)
            .filter(|n| n.allocated && n.is_leaf())
            .map(|n| (n.user_data, n.aabb))
    }

    /// Calls `callback(user_data)` for every proxy whose fat box overlaps
    /// `aabb` (touching counts), until the callback returns `false`.
    ///
    /// Iterative, with a stack on the call stack: no recursion and no heap
    /// allocation.
    #[inline]
    pub fn query<F: FnMut(u32) -> bool>(&self, aabb: &Aabb, mut callback: F) {
        self.query_proxies(aabb, |_, user_data| callback(user_data));
    }

    /// Like [`query`](Self::query) but the callback receives
    /// `(proxy_id, user_data)`.
    pub fn query_proxies<F: FnMut(u32, u32) -> bool>(&self, aabb: &Aabb, callback: F) {
        self.walk(|node| node.aabb.overlaps(aabb), callback);
    }

    /// The depth-first walk behind the queries: descends into the nodes
    /// `enter` accepts and calls `callback(proxy_id, user_data)` for each
    /// accepted leaf, until it returns `false`. Iterative, with a stack on
    /// the call stack.
    #[inline(always)]
    fn walk<F: FnMut(u32, u32) -> bool>(&self, enter: impl Fn(&Node) -> bool, mut callback: F) {
        if self.root == NULL_NODE {
            return;
        }
        let mut stack = NodeStack::new(self.root);
        while let Some(index) = stack.pop() {
            let node = &self.nodes[index as usize];
            if !enter(node) {
                continue;
            }
            if node.is_leaf() {
                if !callback(index, node.user_data) {
                    return;
                }
            } else {
                stack.push(node.child2);
                stack.push(node.child1);
            }
        }
    }

    /// [`query_proxies`](Self::query_proxies) for the proxies whose filter
    /// bits may pair with `bits` (a moved proxy's search for new pairs):
    /// subtrees whose bits cannot are skipped whole.
    pub fn query_proxies_filtered<F: FnMut(u32, u32) -> bool>(
        &self,
        aabb: &Aabb,
        bits: FilterBits,
        callback: F,
    ) {
        self.walk(
            |node| node.bits.may_pair(bits) && node.aabb.overlaps(aabb),
            callback,
        );
    }

    /// Calls `callback(proxy_id, user_data)` for every proxy whose fat box
    /// the segment `origin + s · translation`, `s ∈ [0, max_fraction]`,
    /// touches, in depth-first order, until the callback returns `false`.
    ///
    /// Each node's box is tested with the slab method; a zero translation
    /// visits the boxes that contain `origin`. Iterative, no allocation.
    pub fn ray_query<F: FnMut(u32, u32) -> bool>(
        &self,
        origin: Vec2,
        translation: Vec2,
        max_fraction: Real,
        callback: F,
    ) {
        self.walk(
            |node| segment_touches_box(origin, translation, max_fraction, &node.aabb),
            callback,
        );
    }

    /// Translates every box by `-new_origin` (for large worlds: makes
    /// `new_origin` the new coordinate origin). The tree shape is unchanged.
    pub fn shift_origin(&mut self, new_origin: Vec2) {
        for node in self.nodes.iter_mut().filter(|n| n.allocated) {
            node.aabb.lower -= new_origin;
            node.aabb.upper -= new_origin;
        }
    }

    /// Checks every structural invariant and panics on the first violation
    /// (see [`DynamicTree::check`]). Meant for tests and debugging.
    pub fn validate(&self) {
        if let Err(e) = self.check() {
            panic!("{e}");
        }
    }

    /// Checks every structural invariant without panicking, also on a tree
    /// whose indices are corrupt (a decoded snapshot): indices in range,
    /// parent/child links, heights, internal boxes equal to the union of
    /// their children, leaf and free-list counts, no cycle.
    pub fn check(&self) -> Result<(), String> {
        let node_at = |index: u32| {
            self.nodes
                .get(index as usize)
                .ok_or_else(|| format!("node index {index} out of range"))
        };
        let mut reachable = 0usize;
        let mut leaves = 0usize;
        if self.root != NULL_NODE {
            if node_at(self.root)?.parent != NULL_NODE {
                return Err("root has a parent".into());
            }
            let mut stack: Vec<u32> = vec![self.root];
            while let Some(index) = stack.pop() {
                let node = node_at(index)?;
                if !node.allocated {
                    return Err(format!("node {index} reachable but free"));
                }
                reachable += 1;
                if reachable > self.nodes.len() {
                    return Err("the tree has a cycle".into());
                }
                if node.is_leaf() {
                    if node.child2 != NULL_NODE || node.height != 0 {
                        return Err(format!("leaf {index}: child2 or height"));
                    }
                    leaves += 1;
                    continue;
                }
                let (c1, c2) = (node.child1, node.child2);
                if c2 == NULL_NODE || c1 == c2 {
                    return Err(format!("node {index} children"));
                }
                let (n1, n2) = (node_at(c1)?, node_at(c2)?);
                if n1.parent != index || n2.parent != index {
                    return Err(format!("node {index}: a child's parent link"));
                }
                if node.height != 1 + n1.height.max(n2.height) {
                    return Err(format!("node {index} height"));
                }
                if node.aabb != n1.aabb.union(&n2.aabb) {
                    return Err(format!("node {index} box is not its children's union"));
                }
                if node.bits != n1.bits.union(n2.bits) {
                    return Err(format!("node {index} bits are not its children's union"));
                }
                stack.push(c1);
                stack.push(c2);
            }
        }
        if leaves != self.proxy_count as usize {
            return Err(format!("{leaves} leaves, {} proxies", self.proxy_count));
        }
        if leaves > 0 && reachable != 2 * leaves - 1 {
            return Err(format!("{reachable} nodes for {leaves} leaves"));
        }
        let mut free = 0usize;
        let mut index = self.free_list;
        while index != NULL_NODE {
            let node = node_at(index)?;
            if node.allocated {
                return Err(format!("free node {index} marked allocated"));
            }
            free += 1;
            if free > self.nodes.len() {
                return Err("free list has a cycle".into());
            }
            index = node.parent;
        }
        if reachable + free != self.nodes.len() {
            return Err("leaked nodes".into());
        }
        Ok(())
    }

    /// Marks, per node, whether its subtree holds one of the `leaves`
    /// (node ids of leaves): `marks[n]` for node `n`. Each leaf's path is
    /// walked up to the first node already marked, so the cost is the
    /// number of marked nodes. The pair descents take these marks to skip
    /// node pairs with no marked leaf on either side.
    ///
    /// When a quarter of the proxies or more are listed and the refits'
    /// order is kept (see [`DynamicTree::refit_all`]), the internal marks
    /// are made in that order instead, each node's from its children's:
    /// the same marks, from one pass in memory order rather than a walk of
    /// parent links from each leaf.
    pub(crate) fn mark_paths(
        &self,
        leaves: impl Iterator<Item = u32> + Clone,
        marks: &mut Vec<bool>,
    ) {
        marks.clear();
        marks.resize(self.nodes.len(), false);
        let mut count = 0;
        for leaf in leaves.clone() {
            marks[leaf as usize] = true;
            count += 1;
        }
        if self.refit_order_ready && count * FULL_REBUILD_DIVISOR >= self.proxy_count as usize {
            for &index in &self.refit_order {
                let node = &self.nodes[index as usize];
                marks[index as usize] = marks[node.child1 as usize] || marks[node.child2 as usize];
            }
            return;
        }
        for leaf in leaves {
            let mut index = self.nodes[leaf as usize].parent;
            while index != NULL_NODE && !marks[index as usize] {
                marks[index as usize] = true;
                index = self.nodes[index as usize].parent;
            }
        }
    }

    /// Calls `f(user_a, user_b)` exactly once for every unordered pair of
    /// distinct proxies whose fat boxes overlap, by descending the tree
    /// against itself. `stack` is scratch space (cleared on entry).
    ///
    /// With `marks` (from [`DynamicTree::mark_paths`]; empty: none) only
    /// the pairs with at least one marked leaf are reported: a node pair
    /// with no mark on either side is not descended.
    pub(crate) fn for_each_self_pair<F: FnMut(u32, u32)>(
        &self,
        marks: &[bool],
        stack: &mut Vec<(u32, u32)>,
        f: F,
    ) {
        stack.clear();
        if self.root == NULL_NODE {
            return;
        }
        self.for_each_pair_from(None, marks, (self.root, self.root), stack, f);
    }

    /// Calls `f(user_self, user_other)` for every pair of a proxy of `self`
    /// and a proxy of `other` whose fat boxes overlap; with marks (`marks`
    /// of `self`'s nodes, `other_marks` of `other`'s; empty: none), only
    /// the pairs with a marked leaf on either side.
    pub(crate) fn for_each_cross_pair<F: FnMut(u32, u32)>(
        &self,
        other: &DynamicTree,
        marks: &[bool],
        other_marks: &[bool],
        stack: &mut Vec<(u32, u32)>,
        f: F,
    ) {
        stack.clear();
        if self.root == NULL_NODE || other.root == NULL_NODE {
            return;
        }
        let seed = (self.root, other.root);
        self.for_each_pair_from(Some((other, other_marks)), marks, seed, stack, f);
    }

    /// Starting points of the simultaneous descent that
    /// [`DynamicTree::for_each_self_pair`] (`other: None`) or
    /// [`DynamicTree::for_each_cross_pair`] makes: the descent is expanded
    /// breadth first until at least `want` node pairs are left (or nothing
    /// splits further). Descending from every seed with
    /// [`DynamicTree::for_each_pair_from`] reports every overlapping leaf
    /// pair exactly once, so the seeds can be shared out between threads.
    #[cfg_attr(not(feature = "parallel"), allow(dead_code))]
    pub(crate) fn pair_seeds(
        &self,
        other: Option<&DynamicTree>,
        want: usize,
        seeds: &mut Vec<(u32, u32)>,
    ) {
        seeds.clear();
        let b_tree = other.unwrap_or(self);
        if self.root == NULL_NODE || b_tree.root == NULL_NODE {
            return;
        }
        let mut queue = std::collections::VecDeque::new();
        queue.push_back((self.root, b_tree.root));
        // Leaf pairs and pairs that cannot split are kept as they are.
        while queue.len() + seeds.len() < want {
            let Some((a, b)) = queue.pop_front() else {
                break;
            };
            let na = &self.nodes[a as usize];
            if other.is_none() && a == b {
                if !na.is_leaf() && na.bits.may_pair(na.bits) {
                    queue.push_back((na.child1, na.child1));
                    queue.push_back((na.child2, na.child2));
                    queue.push_back((na.child1, na.child2));
                }
                continue;
            }
            let nb = &b_tree.nodes[b as usize];
            if !na.bits.may_pair(nb.bits) || !na.aabb.overlaps(&nb.aabb) {
                continue;
            }
            match (na.is_leaf(), nb.is_leaf()) {
                (true, true) => seeds.push((a, b)),
                (false, true) => {
                    queue.push_back((na.child1, b));
                    queue.push_back((na.child2, b));
                }
                (true, false) => {
                    queue.push_back((a, nb.child1));
                    queue.push_back((a, nb.child2));
                }
                (false, false) => {
                    if na.aabb.perimeter() >= nb.aabb.perimeter() {
                        queue.push_back((na.child1, b));
                        queue.push_back((na.child2, b));
                    } else {
                        queue.push_back((a, nb.child1));
                        queue.push_back((a, nb.child2));
                    }
                }
            }
        }
        seeds.extend(queue);
    }

    /// The descent of [`DynamicTree::for_each_self_pair`] (`other: None`)
    /// or [`DynamicTree::for_each_cross_pair`] from one seed of
    /// [`DynamicTree::pair_seeds`].
    ///
    /// A node pair goes on the stack only once it has passed its test (a
    /// mark on either side, filters that may pair, boxes that overlap; for
    /// a node against itself, its mark and its own filter): the two
    /// children of a split node are read and tested together, so their
    /// loads overlap, and a pair that fails is never pushed. The pairs
    /// that pass are pushed in the order they always were, so the leaf
    /// pairs are reported in the order of testing after popping.
    pub(crate) fn for_each_pair_from<F: FnMut(u32, u32)>(
        &self,
        other: Option<(&DynamicTree, &[bool])>,
        marks: &[bool],
        seed: (u32, u32),
        stack: &mut Vec<(u32, u32)>,
        mut f: F,
    ) {
        let (b_tree, b_marks) = other.unwrap_or((self, marks));
        let within = other.is_none();
        let a_nodes = &self.nodes[..];
        let b_nodes = &b_tree.nodes[..];
        // The test of a pair of distinct nodes (or of two trees' nodes).
        let passes = |na: &Node, a: u32, nb: &Node, b: u32| {
            (marked(marks, a) || marked(b_marks, b))
                && na.bits.may_pair(nb.bits)
                && na.aabb.overlaps(&nb.aabb)
        };
        // A node against itself: worth descending when marked, internal,
        // and its leaves' filters may pair among themselves.
        let passes_alone =
            |n: &Node, i: u32| marked(marks, i) && !n.is_leaf() && n.bits.may_pair(n.bits);
        stack.clear();
        let (a, b) = seed;
        let seed_passes = if within && a == b {
            passes_alone(&a_nodes[a as usize], a)
        } else {
            passes(&a_nodes[a as usize], a, &b_nodes[b as usize], b)
        };
        if !seed_passes {
            return;
        }
        stack.push(seed);
        while let Some((a, b)) = stack.pop() {
            let na = &a_nodes[a as usize];
            if within && a == b {
                // (Internal: tested before it was pushed.)
                let (c1, c2) = (na.child1, na.child2);
                let (n1, n2) = (&a_nodes[c1 as usize], &a_nodes[c2 as usize]);
                if passes(n1, c1, n2, c2) {
                    stack.push((c1, c2));
                }
                if passes_alone(n2, c2) {
                    stack.push((c2, c2));
                }
                if passes_alone(n1, c1) {
                    stack.push((c1, c1));
                }
                continue;
            }
            let nb = &b_nodes[b as usize];
            let split_a = match (na.is_leaf(), nb.is_leaf()) {
                (true, true) => {
                    f(na.user_data, nb.user_data);
                    continue;
                }
                (false, true) => true,
                (true, false) => false,
                (false, false) => na.aabb.perimeter() >= nb.aabb.perimeter(),
            };
            if split_a {
                let children = children_of(a_nodes, na);
                push_passing(stack, children, |n, c| passes(n, c, nb, b), |c| (c, b));
            } else {
                let children = children_of(b_nodes, nb);
                push_passing(stack, children, |n, c| passes(na, a, n, c), |c| (a, c));
            }
        }
    }

    // ---- internals ----------------------------------------------------

    #[inline(always)]
    fn check_proxy(&self, id: u32) {
        let node = &self.nodes[id as usize];
        assert!(node.allocated && node.is_leaf(), "invalid proxy id {id}");
    }

    fn allocate_node(&mut self) -> u32 {
        self.refit_order_ready = false;
        if self.free_list != NULL_NODE {
            let id = self.free_list;
            let node = &mut self.nodes[id as usize];
            self.free_list = node.parent;
            *node = Node {
                allocated: true,
                ..Node::EMPTY
            };
            id
        } else {
            let id = u32::try_from(self.nodes.len())
                .ok()
                .filter(|&i| i != NULL_NODE)
                .expect("dynamic tree node capacity exceeded");
            self.nodes.push(Node {
                allocated: true,
                ..Node::EMPTY
            });
            id
        }
    }

    fn free_node(&mut self, id: u32) {
        self.refit_order_ready = false;
        self.nodes[id as usize] = Node {
            parent: self.free_list,
            ..Node::EMPTY
        };
        self.free_list = id;
    }

    /// Branch-and-bound search for the node whose pairing with a new leaf of
    /// box `d` adds the least total perimeter to the tree.
    ///
    /// Making node `S` the sibling costs `perimeter(S ∪ D)` for the new parent
    /// plus the growth of every ancestor of `S` (the "inherited" cost). A
    /// subtree rooted at `X` cannot do better than
    /// `inherited(X) + growth(X) + perimeter(D)`, so the descent stops when
    /// both children are bounded above the best cost found so far.
    fn find_best_sibling(&self, d: &Aabb) -> u32 {
        let d_perimeter = d.perimeter();
        let mut node = &self.nodes[self.root as usize];
        let mut best = self.root;
        let mut best_cost = node.aabb.union(d).perimeter();
        // Perimeter growth of `node` when the new leaf goes below it.
        let mut growth = best_cost - node.aabb.perimeter();
        let mut inherited: Real = 0.0;
        while !node.is_leaf() {
            inherited += growth;
            let mut next = NULL_NODE;
            let mut next_lower = Real::INFINITY;
            for child in [node.child1, node.child2] {
                let c = &self.nodes[child as usize];
                let direct = c.aabb.union(d).perimeter();
                let cost = inherited + direct;
                if cost < best_cost {
                    best_cost = cost;
                    best = child;
                }
                if !c.is_leaf() {
                    let child_growth = direct - c.aabb.perimeter();
                    let lower = inherited + child_growth + d_perimeter;
                    if lower < next_lower {
                        next = child;
                        next_lower = lower;
                        growth = child_growth;
                    }
                }
            }
            if next == NULL_NODE || next_lower >= best_cost {
                break;
            }
            node = &self.nodes[next as usize];
        }
        best
    }

    fn insert_leaf(&mut self, leaf: u32) {
        self.refit_order_ready = false;
        if self.root == NULL_NODE {
            self.root = leaf;
            self.nodes[leaf as usize].parent = NULL_NODE;
            return;
        }
        let leaf_aabb = self.nodes[leaf as usize].aabb;
        let leaf_bits = self.nodes[leaf as usize].bits;
        let sibling = self.find_best_sibling(&leaf_aabb);
        let old_parent = self.nodes[sibling as usize].parent;
        let new_parent = self.allocate_node();
        let sibling_node = self.nodes[sibling as usize];
        {
            let p = &mut self.nodes[new_parent as usize];
            p.parent = old_parent;
            p.child1 = sibling;
            p.child2 = leaf;
            p.aabb = sibling_node.aabb.union(&leaf_aabb);
            p.height = sibling_node.height + 1;
            p.bits = sibling_node.bits.union(leaf_bits);
        }
        self.nodes[sibling as usize].parent = new_parent;
        self.nodes[leaf as usize].parent = new_parent;
        if old_parent == NULL_NODE {
            self.root = new_parent;
        } else {
            self.replace_child(old_parent, sibling, new_parent);
        }
        self.rotate(new_parent);
        self.refit_upwards(old_parent);
    }

    fn remove_leaf(&mut self, leaf: u32) {
        self.refit_order_ready = false;
        if leaf == self.root {
            self.root = NULL_NODE;
            return;
        }
        let parent = self.nodes[leaf as usize].parent;
        let p = self.nodes[parent as usize];
        let grand = p.parent;
        let sibling = if p.child1 == leaf { p.child2 } else { p.child1 };
        self.nodes[sibling as usize].parent = grand;
        self.nodes[leaf as usize].parent = NULL_NODE;
        self.free_node(parent);
        if grand == NULL_NODE {
            self.root = sibling;
        } else {
            self.replace_child(grand, parent, sibling);
            self.refit_upwards(grand);
        }
    }

    #[inline]
    fn replace_child(&mut self, parent: u32, old: u32, new: u32) {
        self.refit_order_ready = false;
        let p = &mut self.nodes[parent as usize];
        if p.child1 == old {
            p.child1 = new;
        } else {
            debug_assert_eq!(p.child2, old);
            p.child2 = new;
        }
    }

    /// Recomputes box, height and filter bits of an internal node from its
    /// children.
    #[inline]
    fn refit(&mut self, index: u32) {
        let n = self.nodes[index as usize];
        let c1 = &self.nodes[n.child1 as usize];
        let c2 = &self.nodes[n.child2 as usize];
        let aabb = c1.aabb.union(&c2.aabb);
        let height = 1 + c1.height.max(c2.height);
        let bits = c1.bits.union(c2.bits);
        let node = &mut self.nodes[index as usize];
        node.aabb = aabb;
        node.height = height;
        node.bits = bits;
    }

    /// Refits and rotates from `index` towards the root, stopping at the
    /// first node whose box, height and filter bits come out unchanged (its
    /// ancestors are then unchanged too).
    fn refit_upwards(&mut self, mut index: u32) {
        while index != NULL_NODE {
            let before = self.nodes[index as usize];
            self.refit(index);
            self.rotate(index);
            let after = &self.nodes[index as usize];
            if after.aabb == before.aabb
                && after.height == before.height
                && after.bits == before.bits
            {
                break;
            }
            index = after.parent;
        }
    }

    /// Swaps the subtrees `x` and `y` (neither an ancestor of the other)
    /// between their parents. Boxes and heights are not refitted.
    fn swap_subtrees(&mut self, x: u32, y: u32) {
        let px = self.nodes[x as usize].parent;
        let py = self.nodes[y as usize].parent;
        self.replace_child(px, x, y);
        self.replace_child(py, y, x);
        self.nodes[x as usize].parent = py;
        self.nodes[y as usize].parent = px;
    }

    /// Tries the six child/grandchild swaps below internal node `a` and
    /// applies the one that lowers the summed perimeter the most (the box of
    /// `a` itself never changes). When two children differ in height by more
    /// than one, the swap that balances them best is forced instead, which
    /// bounds the height even when perimeters are degenerate.
    fn rotate(&mut self, a: u32) {
        let na = self.nodes[a as usize];
        if na.height < 2 {
            return;
        }
        let (b, c) = (na.child1, na.child2);
        let nb = self.nodes[b as usize];
        let nc = self.nodes[c as usize];

        let mut best = Rotation::None;
        let mut best_delta: Real = 0.0;
        let mut consider = |r: Rotation, delta: Real| {
            if delta < best_delta {
                best_delta = delta;
                best = r;
            }
        };
        let (b_perimeter, c_perimeter) = (nb.aabb.perimeter(), nc.aabb.perimeter());
        let (mut d, mut e, mut f, mut g) = (NULL_NODE, NULL_NODE, NULL_NODE, NULL_NODE);
        if !nc.is_leaf() {
            (f, g) = (nc.child1, nc.child2);
            let fa = self.nodes[f as usize].aabb;
            let ga = self.nodes[g as usize].aabb;
            consider(Rotation::BF, nb.aabb.union(&ga).perimeter() - c_perimeter);
            consider(Rotation::BG, nb.aabb.union(&fa).perimeter() - c_perimeter);
        }
        if !nb.is_leaf() {
            (d, e) = (nb.child1, nb.child2);
            let da = self.nodes[d as usize].aabb;
            let ea = self.nodes[e as usize].aabb;
            consider(Rotation::CD, nc.aabb.union(&ea).perimeter() - b_perimeter);
            consider(Rotation::CE, nc.aabb.union(&da).perimeter() - b_perimeter);
            if !nc.is_leaf() {
                let fa = self.nodes[f as usize].aabb;
                let ga = self.nodes[g as usize].aabb;
                let base = b_perimeter + c_perimeter;
                consider(
                    Rotation::DF,
                    fa.union(&ea).perimeter() + da.union(&ga).perimeter() - base,
                );
                consider(
                    Rotation::DG,
                    ga.union(&ea).perimeter() + fa.union(&da).perimeter() - base,
                );
            }
        }

        // Height guard: an AVL-style rotation when the children are too
        // unbalanced (promote the taller grandchild of the taller child).
        let (hb, hc) = (nb.height, nc.height);
        if hc > hb + 1 {
            let hf = self.nodes[f as usize].height;
            let hg = self.nodes[g as usize].height;
            best = if hf >= hg { Rotation::BF } else { Rotation::BG };
        } else if hb > hc + 1 {
            let hd = self.nodes[d as usize].height;
            let he = self.nodes[e as usize].height;
            best = if hd >= he { Rotation::CD } else { Rotation::CE };
        } else if best != Rotation::None
            && !self.rotation_keeps_height(best, na.height, b, c, d, e, f, g)
        {
            best = Rotation::None;
        }

        match best {
            Rotation::None => return,
            Rotation::BF => {
                self.swap_subtrees(b, f);
                self.refit(c);
            }
            Rotation::BG => {
                self.swap_subtrees(b, g);
                self.refit(c);
            }
            Rotation::CD => {
                self.swap_subtrees(c, d);
                self.refit(b);
            }
            Rotation::CE => {
                self.swap_subtrees(c, e);
                self.refit(b);
            }
            Rotation::DF => {
                self.swap_subtrees(d, f);
                self.refit(b);
                self.refit(c);
            }
            Rotation::DG => {
                self.swap_subtrees(d, g);
                self.refit(b);
                self.refit(c);
            }
        }
        self.refit(a);
    }

    /// True when applying rotation `r` below a node of height `h` would not
    /// make that node taller.
    fn rotation_keeps_height(
        &self,
        r: Rotation,
        h: u16,
        b: u32,
        c: u32,
        d: u32,
        e: u32,
        f: u32,
        g: u32,
    ) -> bool {
        let hgt = |i: u32| self.nodes[i as usize].height;
        let new_height = match r {
            Rotation::None => return true,
            // A = {F, {B, G}}
            Rotation::BF => hgt(f).max(1 + hgt(b).max(hgt(g))),
            Rotation::BG => hgt(g).max(1 + hgt(b).max(hgt(f))),
            // A = {{C, E}, D}
            Rotation::CD => hgt(d).max(1 + hgt(c).max(hgt(e))),
            Rotation::CE => hgt(e).max(1 + hgt(c).max(hgt(d))),
            // A = {{F, E}, {D, G}}
            Rotation::DF => (1 + hgt(f).max(hgt(e))).max(1 + hgt(d).max(hgt(g))),
            Rotation::DG => (1 + hgt(g).max(hgt(e))).max(1 + hgt(f).max(hgt(d))),
        };
        new_height < h
    }
}

/// Helpers shared by the tests of this module and of the broadphase.
/// True when the segment `origin + s · d`, `s ∈ [0, max_fraction]`, touches
/// the box (slab method; touching counts).
fn segment_touches_box(origin: Vec2, d: Vec2, max_fraction: Real, b: &Aabb) -> bool {
    let (mut lo, mut hi) = (0.0 as Real, max_fraction);
    for (o, dd, l, u) in [
        (origin.x, d.x, b.lower.x, b.upper.x),
        (origin.y, d.y, b.lower.y, b.upper.y),
    ] {
        if dd == 0.0 {
            if o < l || o > u {
                return false;
            }
        } else {
            let inv = 1.0 / dd;
            let (t1, t2) = ((l - o) * inv, (u - o) * inv);
            let (t1, t2) = if t1 <= t2 { (t1, t2) } else { (t2, t1) };
            lo = lo.max(t1);
            hi = hi.min(t2);
            if lo > hi {
                return false;
            }
        }
    }
    true
}

/// A span of the whole-tree rebuild's leaves, `start..end`, to join under
/// `parent` as its first or second child.
#[derive(Clone, Copy)]
struct Span {
    start: usize,
    end: usize,
    /// The first of the span's `end − start − 1` internal slots; the last
    /// one is the span's root.
    slot: usize,
    parent: u32,
    first: bool,
}

impl Span {
    /// Number of leaves.
    fn len(&self) -> usize {
        self.end - self.start
    }

    /// The internal slot (index into the rebuild's slot list) of the
    /// span's root: the last of its own.
    fn root_slot(&self) -> usize {
        self.slot + self.len() - 2
    }

    /// The span split at leaf position `split` into its first and second
    /// halves under `parent` (the span's root): the first half owns the
    /// span's first slots, the second the next ones.
    fn halves(&self, split: usize, parent: u32) -> [Span; 2] {
        [
            Span {
                start: self.start,
                end: split,
                slot: self.slot,
                parent,
                first: true,
            },
            Span {
                start: split,
                end: self.end,
                slot: self.slot + split - self.start - 1,
                parent,
                first: false,
            },
        ]
    }
}

/// What [`build_span`] made: the span's internal nodes (slot, node), its
/// leaves' parents (leaf, parent) and its root (a leaf when the span holds
/// one).
struct BuiltSpan {
    made: Vec<(u32, Node)>,
    leaves: Vec<(u32, u32)>,
    root: u32,
}

/// Builds the subtree of one span of [`DynamicTree::rebuild_from_leaves`]
/// from the shared leaves (`items`, centre and id, in span order) and
/// internal slots, reading only the leaves' boxes from `nodes`. The span's
/// root is left without a parent; the caller hangs it.
fn build_span(nodes: &[Node], items: &[(Vec2, u32)], slots: &[u32], span: Span) -> BuiltSpan {
    const NONE: usize = usize::MAX;
    let base = span.start;
    let mut local = items[span.start..span.end].to_vec();
    let len = local.len();
    let mut made: Vec<(u32, Node)> = Vec::with_capacity(len.saturating_sub(1));
    // Local indices of each made node's children in `made` (NONE: a leaf).
    let mut kids: Vec<[usize; 2]> = Vec::with_capacity(len.saturating_sub(1));
    let mut leaves = Vec::with_capacity(len);
    let mut root = NULL_NODE;
    // Spans still to build, each with its parent's index in `made` (NONE:
    // the span's own root, hung by the caller).
    let mut work = vec![(
        Span {
            parent: NULL_NODE,
            ..span
        },
        NONE,
    )];
    while let Some((part, parent)) = work.pop() {
        let (id, me) = if part.len() == 1 {
            let leaf = local[part.start - base].1;
            if parent != NONE {
                leaves.push((leaf, part.parent));
            }
            (leaf, NONE)
        } else {
            let split = part.start + partition_mid(&mut local[part.start - base..part.end - base]);
            let id = slots[part.root_slot()];
            made.push((
                id,
                Node {
                    allocated: true,
                    parent: part.parent,
                    ..Node::EMPTY
                },
            ));
            kids.push([NONE; 2]);
            let me = made.len() - 1;
            let [first, second] = part.halves(split, id);
            work.push((second, me));
            work.push((first, me));
            (id, me)
        };
        if parent == NONE {
            root = id;
        } else {
            let side = usize::from(!part.first);
            if side == 0 {
                made[parent].1.child1 = id;
            } else {
                made[parent].1.child2 = id;
            }
            kids[parent][side] = me;
        }
    }
    // Children were made after their parents: refit in reverse.
    for k in (0..made.len()).rev() {
        let node = made[k].1;
        let of = |kid: usize, id: u32| {
            let n = if kid == NONE {
                &nodes[id as usize]
            } else {
                &made[kid].1
            };
            (n.aabb, n.height, n.bits)
        };
        let (box1, height1, bits1) = of(kids[k][0], node.child1);
        let (box2, height2, bits2) = of(kids[k][1], node.child2);
        made[k].1.aabb = box1.union(&box2);
        made[k].1.height = 1 + height1.max(height2);
        made[k].1.bits = bits1.union(bits2);
    }
    BuiltSpan { made, leaves, root }
}

/// Nodes per block of the whole rebuild's scan on a team.
const SCAN_BLOCK: usize = 4096;

/// The allocated nodes of `nodes` (whose first is node `first`): each
/// leaf's centre and id onto `leaves`, each internal node's id onto
/// `inner`, in node order.
fn scan_nodes(nodes: &[Node], first: usize, leaves: &mut Vec<(Vec2, u32)>, inner: &mut Vec<u32>) {
    for (i, node) in nodes.iter().enumerate() {
        if !node.allocated {
            continue;
        }
        let id = (first + i) as u32;
        if node.is_leaf() {
            leaves.push((centre_of(&node.aabb), id));
        } else {
            inner.push(id);
        }
    }
}

/// The centre of a box, as the rebuild's splits compare it.
#[inline]
fn centre_of(b: &Aabb) -> Vec2 {
    (b.lower + b.upper) * 0.5
}

/// Reorders `items` (centre, id) so that the first `k` lie below the middle
/// of their centres' box along its longer axis and returns `k` (in
/// `1..len`).
fn partition_mid(items: &mut [(Vec2, u32)]) -> usize {
    let (mut lo, mut hi) = (Vec2::splat(Real::INFINITY), Vec2::splat(Real::NEG_INFINITY));
    for &(c, _) in items.iter() {
        lo = lo.min(c);
        hi = hi.max(c);
    }
    let extent = hi - lo;
    let axis = usize::from(extent.y > extent.x);
    let mid = 0.5 * (lo[axis] + hi[axis]);
    // Branch-free: every item is swapped to the front's end and the end
    // moves past it only when it lies below (the split's sides are as with
    // a test per item; random centres would mispredict half those tests).
    let mut k = 0;
    for j in 0..items.len() {
        let below = items[j].0[axis] < mid;
        items.swap(j, k);
        k += usize::from(below);
    }
    if k == 0 || k == items.len() {
        // Every centre on one side (all equal): halve by count.
        k = items.len() / 2;
    }
    k
}

#[cfg(test)]
pub(crate) mod test_util {
    use janus2d_core::geometry::Aabb;
    use janus2d_core::math::{Real, Vec2};

    /// Small deterministic generator (64-bit LCG, high bits).
    pub(crate) struct Lcg(pub(crate) u64);

    impl Lcg {
        pub(crate) fn next_u32(&mut self) -> u32 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (self.0 >> 32) as u32
        }

        /// Uniform in `[0, 1)`.
        pub(crate) fn unit(&mut self) -> Real {
            (self.next_u32() >> 8) as Real / (1u32 << 24) as Real
        }

        pub(crate) fn range(&mut self, lo: Real, hi: Real) -> Real {
            lo + (hi - lo) * self.unit()
        }

        pub(crate) fn below(&mut self, n: u32) -> u32 {
            ((u64::from(self.next_u32()) * u64::from(n)) >> 32) as u32
        }
    }

    pub(crate) fn boxed(cx: Real, cy: Real, hx: Real, hy: Real) -> Aabb {
        Aabb::new(Vec2::new(cx - hx, cy - hy), Vec2::new(cx + hx, cy + hy))
    }

    pub(crate) fn random_box(rng: &mut Lcg, world: Real) -> Aabb {
        let (cx, cy) = (rng.range(0.0, world), rng.range(0.0, world));
        boxed(cx, cy, rng.range(0.05, 1.0), rng.range(0.05, 1.0))
    }

    pub(crate) fn translate(b: Aabb, d: Vec2) -> Aabb {
        Aabb::new(b.lower + d, b.upper + d)
    }

    /// The payloads `tree.query` reports for `probe`, sorted.
    /// `count` random boxes within `size` (the `q`-th fattened by
    /// `1 + q·grow`) queried in `tree`: each finds exactly the leaves of
    /// `ids` (leaf `i` is `ids[i]`, payload `i`) whose fat boxes overlap it.
    pub(crate) fn queries_match_brute_force(
        tree: &super::DynamicTree,
        ids: &[u32],
        rng: &mut Lcg,
        (count, size, grow): (usize, Real, Real),
        round: usize,
    ) {
        for q in 0..count {
            let probe = random_box(rng, size).fattened(1.0 + q as Real * grow);
            let found = sorted_query(tree, &probe);
            let expected: Vec<u32> = (0..ids.len() as u32)
                .filter(|&i| tree.fat_aabb(ids[i as usize]).overlaps(&probe))
                .collect();
            assert_eq!(found, expected, "round {round}, query {q}");
        }
    }

    pub(crate) fn sorted_query(tree: &super::DynamicTree, probe: &Aabb) -> Vec<u32> {
        let mut found = Vec::new();
        tree.query(probe, |u| {
            found.push(u);
            true
        });
        found.sort_unstable();
        found
    }
}

#[cfg(test)]
mod tests {
    use super::test_util::{
        Lcg, boxed, queries_match_brute_force, random_box, sorted_query, translate,
    };
    use super::*;

    /// A tree decoded from crafted bytes may hold any index: the check
    /// reports it instead of panicking on it (and a sound tree passes).
    #[test]
    fn check_reports_corrupt_indices_without_panicking() {
        let mut tree = DynamicTree::new();
        for i in 0..20u32 {
            tree.create_proxy(boxed(i as Real, 0.0, 0.4, 0.4), i);
        }
        assert_eq!(tree.check(), Ok(()));
        let internal = tree.root as usize;
        for corrupt in [u32::MAX - 1, 1_000_000, tree.root] {
            let mut bad = tree.clone();
            bad.nodes[internal].child1 = corrupt;
            assert!(bad.check().is_err(), "child index {corrupt} passed");
        }
        let mut bad = tree.clone();
        bad.root = 999;
        assert!(bad.check().is_err());
        let mut bad = tree.clone();
        bad.free_list = 12345;
        assert!(bad.check().is_err());
    }

    /// Moves through `enlarge_proxy` followed by one `rebuild` leave a
    /// sound tree (exact boxes, heights, links) that answers every query
    /// as a tree built by insertion does, and stays shallow; a rebuild
    /// with nothing enlarged changes nothing.
    #[test]
    fn enlarge_then_rebuild_matches_insertion() {
        let mut rng = Lcg(11);
        let mut batched = DynamicTree::new();
        let mut inserted = DynamicTree::new();
        let mut boxes: Vec<Aabb> = (0..3000).map(|_| random_box(&mut rng, 120.0)).collect();
        let ids: Vec<u32> = boxes
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let id = batched.create_proxy(*b, i as u32);
                assert_eq!(inserted.create_proxy(*b, i as u32), id);
                id
            })
            .collect();
        let mut items = Vec::new();
        for round in 0..6 {
            // A third of the boxes move; some far (out of their fat box).
            for i in (round % 3..boxes.len()).step_by(3) {
                let d = Vec2::new(rng.range(-2.0, 2.0), rng.range(-2.0, 2.0));
                boxes[i] = translate(boxes[i], d);
                let moved = batched.enlarge_proxy(ids[i], boxes[i]);
                assert_eq!(moved, inserted.move_proxy(ids[i], boxes[i]));
            }
            batched.rebuild(&mut items);
            assert_eq!(batched.check(), Ok(()), "round {round}");
            assert!(batched.height() <= 40, "height {}", batched.height());
            for i in 0..boxes.len() {
                assert_eq!(batched.fat_aabb(ids[i]), inserted.fat_aabb(ids[i]));
            }
            for q in 0..50 {
                let probe = random_box(&mut rng, 120.0).fattened(1.0 + q as Real * 0.1);
                assert_eq!(
                    sorted_query(&batched, &probe),
                    sorted_query(&inserted, &probe),
                    "round {round}, query {q}"
                );
            }
        }
        let before = batched.clone();
        batched.rebuild(&mut items);
        assert!(items.is_empty());
        assert_eq!(
            format!("{:?}", before.nodes),
            format!("{:?}", batched.nodes)
        );
    }

    /// A bulk batch finished by a refit keeps the tree's shape (every
    /// node's parent and children as they were) and leaves it sound: each
    /// internal box exactly its children's union, heights and bits right
    /// (`check`), and every query answered as a brute-force scan answers
    /// it; a rebuild after a few refits is sound too. The refits' kept
    /// order is exercised each way: from a walk (the first rounds), from a
    /// whole rebuild's slots (after round 3), and again from a walk after
    /// proxies were destroyed and created (round 5), each reused once
    /// more.
    #[test]
    fn refitted_bulk_batches_keep_the_shape_and_answer_queries() {
        let mut rng = Lcg(11);
        let mut tree = DynamicTree::new();
        let mut boxes: Vec<Aabb> = (0..2000).map(|_| random_box(&mut rng, 100.0)).collect();
        let mut ids: Vec<u32> = boxes
            .iter()
            .enumerate()
            .map(|(i, b)| tree.create_proxy(*b, i as u32))
            .collect();
        let shape = |t: &DynamicTree| -> Vec<(u32, u32, u32)> {
            t.nodes
                .iter()
                .map(|n| (n.parent, n.child1, n.child2))
                .collect()
        };
        for round in 0..8 {
            if round == 5 {
                // Links change: every tenth proxy out and in again.
                for i in (0..boxes.len()).step_by(10) {
                    tree.destroy_proxy(ids[i]);
                    ids[i] = tree.create_proxy(boxes[i], i as u32);
                }
            }
            for (i, b) in boxes.iter_mut().enumerate() {
                let d = Vec2::new(rng.range(-3.0, 3.0), rng.range(-3.0, 3.0));
                *b = translate(*b, d);
                tree.enlarge_leaf_with_margin(ids[i], *b, 0.1);
            }
            assert!(tree.pending_is_bulk(), "round {round}");
            let finish = if round == 3 || round == 7 {
                BulkFinish::Rebuild
            } else {
                BulkFinish::Refit
            };
            let before = shape(&tree);
            tree.finish_enlarged_with(&mut Vec::new(), &Team::serial(), finish);
            assert_eq!(tree.check(), Ok(()), "round {round}");
            if finish == BulkFinish::Refit {
                assert_eq!(shape(&tree), before, "round {round}: the shape kept");
            }
            queries_match_brute_force(&tree, &ids, &mut rng, (40, 110.0, 0.2), round);
        }
    }

    /// The marks of a bulk batch made in the refits' kept order are the
    /// marks of walking each listed leaf's path: after a refit (the order
    /// from a walk of the tree) and after a whole rebuild (the order from
    /// its slots), for every second and every third leaf listed.
    #[test]
    fn marks_in_the_refit_order_are_the_walked_paths() {
        let mut rng = Lcg(23);
        let mut tree = DynamicTree::new();
        let mut boxes: Vec<Aabb> = (0..3000).map(|_| random_box(&mut rng, 100.0)).collect();
        let ids: Vec<u32> = boxes
            .iter()
            .enumerate()
            .map(|(i, b)| tree.create_proxy(*b, i as u32))
            .collect();
        for finish in [BulkFinish::Refit, BulkFinish::Rebuild] {
            for (i, b) in boxes.iter_mut().enumerate() {
                *b = translate(*b, Vec2::new(rng.range(-3.0, 3.0), rng.range(-3.0, 3.0)));
                tree.enlarge_leaf_with_margin(ids[i], *b, 0.1);
            }
            tree.finish_enlarged_with(&mut Vec::new(), &Team::serial(), finish);
            assert!(tree.refit_order_ready, "{finish:?}: the order kept");
            let mut walked_tree = tree.clone();
            walked_tree.refit_order_ready = false;
            for stride in [2, 3] {
                let listed = ids.iter().copied().step_by(stride);
                let (mut ordered, mut walked) = (Vec::new(), Vec::new());
                tree.mark_paths(listed.clone(), &mut ordered);
                walked_tree.mark_paths(listed, &mut walked);
                assert_eq!(ordered, walked, "{finish:?}, every {stride}th leaf");
                let count = ordered.iter().filter(|&&m| m).count();
                assert!(count > ids.len() / stride, "{finish:?}: {count} marks");
            }
        }
    }

    /// Deferred moves (`enlarge_leaf_with_margin`, then
    /// `finish_enlarged`) give, for a batch of few moves, the very tree of
    /// immediate ones (`enlarge_proxy_with_margin`, then `rebuild`); for a
    /// batch of many, a whole rebuild that is sound, answers every query as
    /// a brute-force scan does, stays shallow, and comes out node for node
    /// the same on a team of 1, 2 or 4 threads. (4,500 boxes: about 9,000
    /// nodes, so that the rebuild's scan runs in blocks on the team.)
    #[test]
    fn deferred_moves_match_immediate_ones_and_a_whole_rebuild_any_team() {
        let mut rng = Lcg(5);
        let mut deferred = DynamicTree::new();
        let mut boxes: Vec<Aabb> = (0..4500).map(|_| random_box(&mut rng, 120.0)).collect();
        assert!(2 * boxes.len() > 2 * SCAN_BLOCK, "the scan's blocked path");
        let ids: Vec<u32> = boxes
            .iter()
            .enumerate()
            .map(|(i, b)| deferred.create_proxy(*b, i as u32))
            .collect();
        let mut items = Vec::new();
        for round in 0..6 {
            // Few moves (every 20th box) on even rounds, many (every other
            // box) on odd ones.
            let stride = if round % 2 == 0 { 20 } else { 2 };
            let mut immediate = deferred.clone();
            let mut moved = 0;
            for i in (round % stride..boxes.len()).step_by(stride) {
                let d = Vec2::new(rng.range(-2.0, 2.0), rng.range(-2.0, 2.0));
                boxes[i] = translate(boxes[i], d);
                let now = immediate.enlarge_proxy_with_margin(ids[i], boxes[i], 0.1);
                assert_eq!(
                    now,
                    deferred.enlarge_leaf_with_margin(ids[i], boxes[i], 0.1)
                );
                moved += usize::from(now);
            }
            let bulk = deferred.pending_is_bulk();
            assert_eq!(bulk, round % 2 == 1, "round {round}: {moved} moved");
            // The same batch, kept to finish on larger teams below.
            #[cfg(feature = "parallel")]
            let on_teams = bulk.then(|| deferred.clone());
            deferred.finish_enlarged(&mut items, &Team::serial());
            assert_eq!(deferred.check(), Ok(()), "round {round}");
            assert!(deferred.pending.is_empty());
            if bulk {
                assert!(deferred.height() <= 30, "height {}", deferred.height());
                #[cfg(feature = "parallel")]
                for threads in [2, 4] {
                    let mut tree = on_teams.clone().unwrap();
                    janus2d_core::parallel::with_threads(threads, |team| {
                        tree.finish_enlarged(&mut Vec::new(), team);
                    })
                    .unwrap();
                    assert_eq!(
                        format!("{:?}", tree.nodes),
                        format!("{:?}", deferred.nodes),
                        "round {round}, {threads} threads"
                    );
                }
            } else {
                immediate.rebuild(&mut items);
                assert_eq!(
                    format!("{:?}", immediate.nodes),
                    format!("{:?}", deferred.nodes),
                    "round {round}"
                );
            }
            queries_match_brute_force(&deferred, &ids, &mut rng, (50, 120.0, 0.1), round);
        }
    }

    /// Descending from the seeds reports the same pairs as the full
    /// descent, each once, for any number of seeds (self and cross pairs);
    /// with marked leaves, every descent reports exactly the pairs with a
    /// marked leaf.
    #[test]
    fn seeded_descent_reports_every_pair_once() {
        let mut rng = Lcg(7);
        let mut a = DynamicTree::new();
        let mut b = DynamicTree::new();
        let (mut a_marked, mut b_marked) = (Vec::new(), Vec::new());
        for i in 0..1500u32 {
            let leaf = a.create_proxy(random_box(&mut rng, 60.0), i);
            if i % 5 == 0 {
                a_marked.push((leaf, i));
            }
            if i % 3 == 0 {
                let leaf = b.create_proxy(random_box(&mut rng, 60.0), 10_000 + i);
                if i % 7 == 0 {
                    b_marked.push((leaf, 10_000 + i));
                }
            }
        }
        let (mut a_marks, mut b_marks) = (Vec::new(), Vec::new());
        a.mark_paths(a_marked.iter().map(|m| m.0), &mut a_marks);
        b.mark_paths(b_marked.iter().map(|m| m.0), &mut b_marks);
        let is_marked = |user: u32| a_marked.iter().chain(&b_marked).any(|m| m.1 == user);
        let mut stack = Vec::new();
        for with_marks in [false, true] {
            let (am, bm): (&[bool], &[bool]) = if with_marks {
                (&a_marks, &b_marks)
            } else {
                (&[], &[])
            };
            for other in [None, Some(&b)] {
                let mut full = Vec::new();
                match other {
                    None => a.for_each_self_pair(&[], &mut stack, |x, y| {
                        full.push((x.min(y), x.max(y)));
                    }),
                    Some(o) => a.for_each_cross_pair(o, &[], &[], &mut stack, |x, y| {
                        full.push((x, y));
                    }),
                }
                full.sort_unstable();
                assert!(full.len() > 1000, "too few pairs: {}", full.len());
                if with_marks {
                    full.retain(|&(x, y)| is_marked(x) || is_marked(y));
                    assert!(full.len() > 100, "too few marked pairs: {}", full.len());
                    let mut pruned = Vec::new();
                    match other {
                        None => a.for_each_self_pair(am, &mut stack, |x, y| {
                            pruned.push((x.min(y), x.max(y)));
                        }),
                        Some(o) => a.for_each_cross_pair(o, am, bm, &mut stack, |x, y| {
                            pruned.push((x, y));
                        }),
                    }
                    pruned.sort_unstable();
                    assert_eq!(pruned, full, "marked full descent");
                }
                for want in [1, 7, 64, 500] {
                    let mut seeds = Vec::new();
                    a.pair_seeds(other, want, &mut seeds);
                    let mut seeded = Vec::new();
                    for &seed in &seeds {
                        a.for_each_pair_from(
                            other.map(|o| (o, bm)),
                            am,
                            seed,
                            &mut stack,
                            |x, y| {
                                seeded.push(if other.is_none() {
                                    (x.min(y), x.max(y))
                                } else {
                                    (x, y)
                                });
                            },
                        );
                    }
                    seeded.sort_unstable();
                    assert_eq!(seeded, full, "want {want}, {} seeds", seeds.len());
                }
            }
        }
    }

    #[test]
    fn a_ground_inserted_row_by_row_is_rebuilt_balanced_with_the_same_overlaps() {
        // Rain's ground: 5 rows 45 m apart of 501 boxes of half-width
        // 0.25 m, inserted box by box along each row.
        let mut tree = DynamicTree::with_margin(0.0);
        let mut id = 0;
        for row in 0..5 {
            for j in 0..=500 {
                let (x, y) = (-125.0 + 0.5 * j as Real, 45.0 * row as Real);
                tree.create_proxy(boxed(x, y, 0.25, 0.25), id);
                id += 1;
            }
        }
        assert!(tree.is_unbalanced(), "height {}", tree.height());
        let (height, ratio) = (tree.height(), tree.area_ratio());
        let probes: Vec<Aabb> = (0..50)
            .map(|k| boxed(-130.0 + 5.3 * k as Real, 45.0 * (k % 5) as Real, 0.8, 0.6))
            .collect();
        let hits = |t: &DynamicTree| -> Vec<Vec<u32>> {
            probes.iter().map(|b| sorted_query(t, b)).collect()
        };
        let before = hits(&tree);
        tree.rebuild_all(&mut Vec::new());
        tree.validate();
        assert!(!tree.is_unbalanced());
        // ⌈log₂ 2,505⌉ = 12.
        assert!(tree.height() <= 13, "height {height} -> {}", tree.height());
        assert!(
            tree.area_ratio() < 0.5 * ratio,
            "area ratio {ratio} -> {}",
            tree.area_ratio()
        );
        assert_eq!(hits(&tree), before);
        assert!(
            before.iter().any(|h| h.len() > 4),
            "the probes touch the ground"
        );
    }

    #[test]
    fn sorted_insertion_stays_balanced_and_removal_validates() {
        let n = 10_000u32;
        let bound = |count: usize| 2.0 * (count as f64).log2() + 4.0;
        // A row of unit boxes, inserted left to right.
        let mut tree = DynamicTree::new();
        let ids: Vec<u32> = (0..n)
            .map(|i| tree.create_proxy(boxed(i as Real * 1.1, 0.0, 0.5, 0.5), i))
            .collect();
        tree.validate();
        assert_eq!(tree.proxy_count(), n as usize);
        let h = tree.height();
        assert!(f64::from(h) <= bound(n as usize), "row height {h}");
        assert!(h >= 14, "height {h} below log2(n)");

        // Remove every other proxy.
        for &id in ids.iter().step_by(2) {
            tree.destroy_proxy(id);
        }
        tree.validate();
        assert_eq!(tree.proxy_count(), (n / 2) as usize);
        let h = tree.height();
        assert!(
            f64::from(h) <= bound((n / 2) as usize),
            "height after removal {h}"
        );
        for (i, &id) in ids.iter().enumerate().skip(1).step_by(2) {
            assert_eq!(tree.user_data(id), i as u32);
        }

        // Remove the rest in a scrambled order, validating periodically.
        let mut rest: Vec<u32> = ids.iter().copied().skip(1).step_by(2).collect();
        let mut rng = Lcg(3);
        for i in (1..rest.len()).rev() {
            let j = rng.below(i as u32 + 1) as usize;
            rest.swap(i, j);
        }
        for (k, &id) in rest.iter().enumerate() {
            tree.destroy_proxy(id);
            if k % 997 == 0 {
                tree.validate();
            }
        }
        tree.validate();
        assert!(tree.is_empty());
        assert_eq!(tree.height(), 0);

        // Node slots are recycled: refilling does not grow the node array.
        let capacity = tree.nodes.len();
        for i in 0..n {
            tree.create_proxy(boxed(0.0, i as Real * 1.1, 0.5, 0.5), i);
        }
        tree.validate();
        assert_eq!(tree.nodes.len(), capacity);
        let h = tree.height();
        assert!(f64::from(h) <= bound(n as usize), "column height {h}");

        // A 100 x 100 grid in row-major order.
        let mut grid = DynamicTree::new();
        for i in 0..n {
            let (x, y) = ((i % 100) as Real, (i / 100) as Real);
            grid.create_proxy(boxed(x, y, 0.5, 0.5), i);
        }
        grid.validate();
        let h = grid.height();
        assert!(f64::from(h) <= bound(n as usize), "grid height {h}");
    }

    #[test]
    fn ray_query_matches_brute_force_slab_test() {
        let mut rng = Lcg(11);
        let mut tree = DynamicTree::with_margin(0.0);
        let boxes: Vec<Aabb> = (0..2000).map(|_| random_box(&mut rng, 60.0)).collect();
        for (i, b) in boxes.iter().enumerate() {
            tree.create_proxy(*b, i as u32);
        }
        for _ in 0..50 {
            let origin = Vec2::new(rng.range(-5.0, 65.0), rng.range(-5.0, 65.0));
            let d = Vec2::new(rng.range(-40.0, 40.0), rng.range(-40.0, 40.0));
            let max_fraction = rng.range(0.2, 1.0);
            let mut got = Vec::new();
            tree.ray_query(origin, d, max_fraction, |_, u| {
                got.push(u);
                true
            });
            got.sort_unstable();
            let want: Vec<u32> = (0..boxes.len() as u32)
                .filter(|&i| segment_touches_box(origin, d, max_fraction, &boxes[i as usize]))
                .collect();
            assert_eq!(got, want);
        }
        // A horizontal ray through a row of boxes: exactly the ones it crosses.
        let mut row = DynamicTree::with_margin(0.0);
        for i in 0..10 {
            row.create_proxy(boxed(i as Real * 2.0, 0.0, 0.5, 0.5), i);
        }
        let mut got = Vec::new();
        row.ray_query(Vec2::new(-1.0, 0.2), Vec2::new(8.0, 0.0), 1.0, |_, u| {
            got.push(u);
            true
        });
        got.sort_unstable();
        assert_eq!(got, vec![0, 1, 2, 3]);
        // Stops when the callback says so.
        let mut count = 0;
        row.ray_query(Vec2::new(-1.0, 0.2), Vec2::new(30.0, 0.0), 1.0, |_, _| {
            count += 1;
            false
        });
        assert_eq!(count, 1);
    }

    /// Whatever two full filters let collide (`Filter::should_collide`,
    /// groups included), their 16-bit forms may pair: the descents never
    /// skip a pair the world would keep. And the forms are exact below
    /// category 15 without groups.
    #[test]
    fn filter_bits_never_refuse_what_the_full_filter_allows() {
        let mut rng = Lcg(5);
        let word = |rng: &mut Lcg| {
            // Mostly low categories, sometimes high ones, sometimes all.
            let pick = |rng: &mut Lcg| {
                1u64 << (if rng.below(3) == 0 {
                    15 + rng.below(49)
                } else {
                    rng.below(15)
                })
            };
            match rng.below(6) {
                0 => u64::MAX,
                1 => !pick(rng),
                _ => pick(rng) | pick(rng),
            }
        };
        let (mut allowed, mut refused_exactly) = (0, 0);
        for _ in 0..20_000 {
            let group = |rng: &mut Lcg| [0, 0, -1, 1, 2][rng.below(5) as usize];
            let a = crate::Filter::new(word(&mut rng), word(&mut rng)).with_group(group(&mut rng));
            let b = crate::Filter::new(word(&mut rng), word(&mut rng)).with_group(group(&mut rng));
            let may = a.bits().may_pair(b.bits());
            if a.should_collide(&b) {
                allowed += 1;
                assert!(may, "{a:?} and {b:?} collide but their bits refuse");
            }
            // Below category 15, without groups: exact.
            let low = |rng: &mut Lcg| u64::from(rng.next_u32()) & ((1 << 15) - 1);
            let a = crate::Filter::new(low(&mut rng), low(&mut rng) & low(&mut rng));
            let b = crate::Filter::new(1 << rng.below(15), low(&mut rng) & low(&mut rng));
            let exact = a.should_collide(&b);
            assert_eq!(a.bits().may_pair(b.bits()), exact, "{a:?} {b:?}");
            refused_exactly += usize::from(!exact);
        }
        assert!(
            allowed > 3000 && refused_exactly > 300,
            "{allowed} {refused_exactly}"
        );
    }

    /// The pair descents and the filtered query skip node pairs by their
    /// filter bits and still report exactly the overlapping pairs whose
    /// leaves' bits may pair (brute force over every leaf pair), through
    /// inserts, removals, a filter change, enlarged moves, the partial and
    /// the whole-tree rebuild; a tree whose leaves all refuse each other is
    /// not descended at all.
    #[test]
    fn filter_bits_prune_exactly_the_pairs_that_cannot_pass() {
        let mut rng = Lcg(11);
        // Categories 1, 2 and 4: 1 meets all, 2 meets 1 only, 4 meets 1 and 4.
        let filters = [
            FilterBits::of(1, u64::MAX, 0),
            FilterBits::of(2, 1, 0),
            FilterBits::of(4, 5, 0),
            FilterBits::of(1 << 33, 1 << 33, 0), // bit 15 of the 16: meets itself only
            FilterBits::of(1, u64::MAX, -7),     // meets all but its own group
        ];
        let mut tree = DynamicTree::new();
        let mut other = DynamicTree::new();
        let mut leaves: Vec<(u32, FilterBits)> = Vec::new();
        for i in 0..1200u32 {
            let bits = filters[rng.below(5) as usize];
            let id = tree.create_proxy_filtered(random_box(&mut rng, 50.0), i, 0.1, bits);
            leaves.push((id, bits));
        }
        let mut fixed = Vec::new();
        for i in 0..300u32 {
            let bits = filters[rng.below(5) as usize];
            fixed.push((
                other.create_proxy_filtered(random_box(&mut rng, 50.0), 5000 + i, 0.0, bits),
                bits,
            ));
        }
        let brute_self = |tree: &DynamicTree, leaves: &[(u32, FilterBits)]| {
            let mut want = Vec::new();
            for (k, &(x, bx)) in leaves.iter().enumerate() {
                for &(y, by) in &leaves[k + 1..] {
                    if bx.may_pair(by) && tree.fat_aabb(x).overlaps(&tree.fat_aabb(y)) {
                        let (ux, uy) = (tree.user_data(x), tree.user_data(y));
                        want.push((ux.min(uy), ux.max(uy)));
                    }
                }
            }
            want.sort_unstable();
            want
        };
        let descended = |tree: &DynamicTree| {
            let mut got = Vec::new();
            tree.for_each_self_pair(&[], &mut Vec::new(), |x, y| got.push((x.min(y), x.max(y))));
            got.sort_unstable();
            got
        };
        let check = |tree: &DynamicTree, leaves: &[(u32, FilterBits)]| {
            tree.validate();
            let want = brute_self(tree, leaves);
            assert!(want.len() > 200, "too few pairs: {}", want.len());
            assert_eq!(descended(tree), want, "self descent");
            let mut seeded = Vec::new();
            let mut seeds = Vec::new();
            tree.pair_seeds(None, 50, &mut seeds);
            for &seed in &seeds {
                tree.for_each_pair_from(None, &[], seed, &mut Vec::new(), |x, y| {
                    seeded.push((x.min(y), x.max(y)));
                });
            }
            seeded.sort_unstable();
            assert_eq!(seeded, want, "seeded descent");
            // Each leaf's filtered query finds its partners of the brute force.
            for &(x, bx) in leaves.iter().step_by(37) {
                let ux = tree.user_data(x);
                let mut found = Vec::new();
                tree.query_proxies_filtered(&tree.fat_aabb(x), bx, |id, u| {
                    if id != x {
                        found.push((ux.min(u), ux.max(u)));
                    }
                    true
                });
                found.sort_unstable();
                let mine: Vec<_> = want
                    .iter()
                    .copied()
                    .filter(|p| p.0 == ux || p.1 == ux)
                    .collect();
                assert_eq!(found, mine, "filtered query of leaf {x}");
            }
        };
        check(&tree, &leaves);
        // Cross pairs against a second tree.
        let mut cross = Vec::new();
        tree.for_each_cross_pair(&other, &[], &[], &mut Vec::new(), |x, y| cross.push((x, y)));
        cross.sort_unstable();
        let mut want = Vec::new();
        for &(x, bx) in &leaves {
            for &(y, by) in &fixed {
                if bx.may_pair(by) && tree.fat_aabb(x).overlaps(&other.fat_aabb(y)) {
                    want.push((tree.user_data(x), other.user_data(y)));
                }
            }
        }
        want.sort_unstable();
        assert!(want.len() > 50, "too few cross pairs: {}", want.len());
        assert_eq!(cross, want, "cross descent");
        // Removals, a filter change, enlarged moves and both rebuilds.
        for k in (0..leaves.len()).step_by(9).rev() {
            tree.destroy_proxy(leaves.remove(k).0);
        }
        for k in (0..leaves.len()).step_by(5) {
            let bits = filters[(k / 5) % 5];
            tree.set_proxy_bits(leaves[k].0, bits);
            leaves[k].1 = bits;
        }
        check(&tree, &leaves);
        let mut items = Vec::new();
        for (round, share) in [(0, 20), (1, 2)] {
            for &(id, _) in leaves.iter().step_by(share) {
                let moved = translate(tree.fat_aabb(id), Vec2::new(0.7 + round as Real, -0.4));
                tree.enlarge_leaf_with_margin(id, moved, 0.1);
            }
            tree.finish_enlarged(&mut items, &Team::serial());
            check(&tree, &leaves);
        }
        // Every leaf refuses every other: the root's bits say so, and no
        // node pair is descended.
        let mut lonely = DynamicTree::new();
        for i in 0..500u32 {
            lonely.create_proxy_filtered(
                random_box(&mut rng, 10.0),
                i,
                0.1,
                FilterBits::of(2, !2, 0),
            );
        }
        assert!(!lonely.may_pair_within());
        assert!(descended(&lonely).is_empty());
        let mut all = lonely.clone();
        for i in 0..5u32 {
            all.create_proxy_filtered(random_box(&mut rng, 10.0), 900 + i, 0.1, FilterBits::ALL);
        }
        assert!(all.may_pair_within());
        assert!(
            !descended(&all).is_empty(),
            "a shape of every category meets the others"
        );
    }

    #[test]
    fn query_matches_brute_force_and_stops_early() {
        let mut rng = Lcg(4);
        let mut tree = DynamicTree::with_margin(0.25);
        let boxes: Vec<Aabb> = (0..3000).map(|_| random_box(&mut rng, 80.0)).collect();
        let ids: Vec<u32> = boxes
            .iter()
            .enumerate()
            .map(|(i, b)| tree.create_proxy(*b, i as u32))
            .collect();
        for (i, &id) in ids.iter().enumerate() {
            assert_eq!(tree.fat_aabb(id), boxes[i].fattened(0.25));
            assert!(!tree.move_proxy(id, translate(boxes[i], Vec2::new(0.2, -0.2))));
        }
        let mut total = 0;
        for _ in 0..50 {
            let q = boxed(rng.range(0.0, 80.0), rng.range(0.0, 80.0), 5.0, 3.0);
            let found = sorted_query(&tree, &q);
            let expected: Vec<u32> = (0..boxes.len() as u32)
                .filter(|&i| boxes[i as usize].fattened(0.25).overlaps(&q))
                .collect();
            assert_eq!(found, expected);
            total += found.len();

            let mut visits = 0;
            tree.query(&q, |_| {
                visits += 1;
                visits < 3
            });
            assert_eq!(visits, expected.len().min(3));
        }
        assert!(total > 200);

        // Shifting the origin moves every box and keeps the tree valid.
        let shift = Vec2::new(10.0, -20.0);
        tree.shift_origin(shift);
        tree.validate();
        for (i, &id) in ids.iter().enumerate() {
            let expected = boxes[i].fattened(0.25);
            assert_eq!(tree.fat_aabb(id).lower, expected.lower - shift);
        }
    }

    #[test]
    fn node_stack_spills_in_lifo_order() {
        let mut stack = NodeStack::new(0);
        for i in 1..200u32 {
            stack.push(i);
        }
        for i in (0..200u32).rev() {
            assert_eq!(stack.pop(), Some(i));
        }
        assert_eq!(stack.pop(), None);
    }
}
