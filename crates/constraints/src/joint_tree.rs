//! Direct solve of the joints' point rows where the joints form a tree.
//!
//! Gauss–Seidel moves information one joint per iteration and builds a soft
//! joint's spring on the *light* body's effective mass, so a heavy load on a
//! chain of light links (the "ball and chain", 670:1) stretches every joint
//! by about `F K / ω²`. Where the joints form a tree, the point rows of the
//! whole tree can instead be solved exactly in time linear in its size
//! (the idea of Baraff, *Linear-time dynamics using Lagrange multipliers*,
//! 1996), and an exact solve stays stable at any stiffness.
//!
//! # Derivation
//!
//! Unknowns: the velocity change `Δv_i = (Δv_x, Δv_y, Δω)` of every moving
//! body in the tree and the impulse change `Δλ_j` (2 rows) of every joint.
//! With `J_ji` the 2×3 block of joint `j` on body `i`
//!
//! ```text
//! J_jb = [ 1 0 −r_b.y ]      J_ja = −[ 1 0 −r_a.y ]      (Ċ = v_b + ω_b × r_b − v_a − ω_a × r_a)
//!        [ 0 1  r_b.x ]              [ 0 1  r_a.x ]
//! ```
//!
//! the soft rows of [`Softness`](janus2d_core::softness::Softness) solved
//! to convergence are
//!
//! ```text
//! M_i Δv_i = Σ_j J_jiᵀ Δλ_j                                  (bodies)
//! Σ_i J_ji Δv_i + Γ_j Δλ_j = −(Ċ_j + β C_j + Γ_j λ_j)        (joints, with bias)
//! Σ_i J_ji Δv_i + Γ_j Δλ_j = −Ċ_j                            (joints, relax)
//! Γ_j = K_j / a2,   K_j = Σ_i J_ji M_i⁻¹ J_jiᵀ,   a2 = mass_scale / impulse_scale
//! ```
//!
//! (for one joint alone this is exactly the soft row `Δλ = −s_m K⁻¹(Ċ + βC) −
//! s_i λ`). With `μ_j = −Δλ_j` the system is symmetric:
//!
//! ```text
//! H x = b,   H = [ M   Jᵀ ]    x = [ Δv ]    b = [ 0 ]
//!                [ J  −Γ  ]        [ μ  ]        [ r ]
//! ```
//!
//! The graph of `H` has a node per moving body and per joint and an edge per
//! (joint, body) pair; static and kinematic bodies are not nodes (a joint to
//! one has a single edge). When the joints form a forest, so does this
//! graph, and block elimination from the leaves up creates no fill:
//!
//! ```text
//!           body ── joint ── body ── joint ── body      eliminate leaves first:
//!  root ─┤                                              D_k  = H_kk − Σ_children L_c E_cᵀ
//!           joint (to a static pin)                     L_k  = E_k D_k⁻¹   (E_k = H_parent,k)
//!                                                       b_p −= L_k b_k
//!  back substitution, root first:   x_k = D_k⁻¹ b_k − L_kᵀ x_parent
//! ```
//!
//! **Geometric stiffness.** The Jacobians are fixed over a substep, so the
//! way a joint's force turns with its body (the geometric stiffness) is
//! integrated explicitly. For `C = p_b + R_b r_b − p_a − R_a r_a` the
//! Hessian of `λ · C` has only angle terms, `∂²/∂θ_b² = −λ · r_b` and
//! `∂²/∂θ_a² = λ · r_a`: under tension (`λ · r_b > 0` on b) a restoring
//! torque of stiffness `λ · r / h` per radian. A taut chain's zig-zag mode
//! (light links alternately turning under a heavy load) then grows once
//! `K_g / I > 4` with `K_g = h Σ max(0, ±λ · r)` summed over a body's
//! joints (`λ` the kept per-substep impulse): a 1000:1 load on 20 links of
//! 1 kg reaches `K_g / I ≈ 5` at the bottom of its swing, and the middle
//! joints opened to 1.75 m.
//! Treating that stiffness implicitly adds `K_g` to the body's inertia
//! (the diagonal geometric stiffness of Andrews et al., *Geometric
//! stiffness for real-time constrained multibody dynamics*, 2017); the tree
//! adds only what keeps the explicit ratio at `GEOMETRIC_RATIO`,
//! `Ĩ = max(I, K_g / 2.5)`, so bodies far from the limit keep their own
//! inertia. The solve's body pivots use `Ĩ`, its impulses act through `Ĩ`
//! (linear momentum is untouched), and the bias pass first re-weights the
//! warm start's torque `r × λ`, applied earlier through `I`, to `Ĩ`.
//!
//! Body pivots stay positive definite and joint pivots negative definite,
//! so the 3×3 block inverses need no pivoting. The elimination runs in f64
//! whatever [`Real`] is: the pivots of a 670:1 chain cost about four digits,
//! which f32 does not have to spare (measured: 3e-3 relative residual in
//! f32 arithmetic at a mass spread of 1e4, 1e-11 in f64), and scalar f64 costs
//! the same as f32 here. A joint block has 2 rows; it
//! is padded to 3×3 with `−1` on the unused diagonal. A body that cannot
//! translate (or rotate) gets the placeholder mass 1 on that axis and a zero
//! Jacobian column, so its `Δv` there is exactly zero.
//!
//! Only joint components without a loop are solved directly (found by
//! union–find over the moving bodies; a static, kinematic or sleeping body
//! is a fixed end, so a bridge pinned at both ends is still a tree). A
//! component with a loop (a joint grid, a cloth) stays wholly iterative:
//! mixing a stiff exact tree with soft Gauss–Seidel rows that close its loops
//! measured unstable (the 40×40 joint grid diverged at 240 Hz). Every
//! joint's angle rows (springs, motors, limits) stay iterative too, solved
//! in the sweep before the contacts; the tree solve runs in the solver's
//! late pass, after the contacts (a block Gauss–Seidel with one exact block
//! that has the last word). Measured on Box2D's `rain`: with the tree
//! before the contacts its ragdolls never settled in the piles (10,989 of
//! 11,001 bodies awake at step 1,000; Gauss–Seidel joints 10,175); after
//! them 9,713 (Gauss–Seidel joints in the same order 9,515; Box2D
//! 10,252). The motors stay before the contacts: a motor with the last
//! word drives its body through whatever it pushes (the spinner's paddle
//! pressed bodies through the one-sided loop).

use glam::{DMat3 as Matrix3, DVec2, DVec3 as Vec3};
use janus2d_core::body::BodySet;
use janus2d_core::body::BodyState;
use janus2d_core::constraint::{Constraint, ConstraintBatch, StepContext};
use janus2d_core::math::{Real, Vec2, cross, cross_sv, from_f64, to_f64};
use janus2d_core::parallel::Team;
use janus2d_core::union_find::{find, union};

use crate::parts::clamp_length;
use crate::revolute::RevoluteJoint;

const NONE: u32 = u32::MAX;

/// Largest ratio `K_g / Ĩ` of a body's geometric stiffness term to the
/// inertia the tree solve gives it (see the module docs): the explicit part
/// of a taut chain's zig-zag mode is stable below 4; 2.5 leaves a margin.
const GEOMETRIC_RATIO: f64 = 2.5;

/// One node of the elimination tree: a moving body or a joint.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Node {
    /// Body: its state index. Joint: its index in the joint slice.
    index: u32,
    /// Parent node (`NONE` for a root). Parents come before children.
    parent: u32,
    /// True for a joint node.
    is_joint: bool,
    /// Which side of the joint the body is: +1 for body b, −1 for body a.
    /// A body node: its side in its parent joint. A joint node: the side of
    /// its parent body.
    side: f64,
}

/// One node's scratch in the tree solve.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct NodeScratch {
    /// The pivot `D_k` while eliminating, then `D_k⁻¹`.
    d: Matrix3,
    /// `L_k = E_k D_k⁻¹`.
    l: Matrix3,
    /// The right-hand side, then the solution.
    b: Vec3,
    /// Joint node: the arms `r_a`, `r_b` of this iteration.
    arms: (Vec2, Vec2),
    /// Body node: first the geometric stiffness term `K_g = h Σ max(0, ±λ ·
    /// r)`, then the inertia added for it, `max(0, K_g / GEOMETRIC_RATIO −
    /// I)` (see the module docs), kg·m².
    geometric: f64,
    /// Joint node: its child body node, tree-local (`NONE` for a fixed end).
    child: u32,
    /// Body node: a copy of its state while the tree is solved.
    state: BodyState,
    /// Joint node: a copy of its accumulated point impulse, N·s.
    impulse: Vec2,
}

impl NodeScratch {
    const ZERO: NodeScratch = NodeScratch {
        d: Matrix3::ZERO,
        l: Matrix3::ZERO,
        b: Vec3::ZERO,
        arms: (Vec2::ZERO, Vec2::ZERO),
        geometric: 0.0,
        child: NONE,
        state: BodyState::IDENTITY,
        impulse: Vec2::ZERO,
    };
}

impl Default for NodeScratch {
    fn default() -> Self {
        Self::ZERO
    }
}

/// The joint forest of one step and the scratch space of its solve.
///
/// Built in `prepare` from the joints' state indices (so sleeping, static
/// and kinematic bodies are the fixed ends), solved in every solve and relax
/// iteration. Deterministic: joints are visited in storage order.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct JointForest {
    /// Nodes, parents first (breadth-first from each root).
    nodes: Vec<Node>,
    /// First node of each tree (a tree's nodes are contiguous).
    trees: Vec<u32>,
    /// Per node: the solve's scratch.
    scratch: Vec<NodeScratch>,
    /// Per joint: its moving ends this step (see `moving_pair`).
    pairs: Vec<[u32; 3]>,
    /// The pairs and switch the forest was last built from.
    built_pairs: Vec<[u32; 3]>,
    built_enabled: bool,
    // Build scratch.
    union: Vec<u32>,
    cyclic: Vec<bool>,
    adjacency_start: Vec<u32>,
    adjacency: Vec<u32>,
    visited: Vec<bool>,
    tree_joints: Vec<u32>,
}

/// A body that the tree moves: dynamic (some inverse mass or inertia).
#[inline]
fn is_moving(states: &[BodyState], s: u32) -> bool {
    s != 0 && {
        let st = &states[s as usize];
        st.inv_mass > 0.0 || st.inv_inertia > 0.0
    }
}

/// A joint's two state indices, 0 for an end the tree does not move
/// (static, kinematic, sleeping), `[0, 0]` for a disabled joint; and its
/// `in_tree` flag, so that a joint created since the last build (flag
/// unset) forces a rebuild even where the ends repeat.
#[inline]
fn moving_pair(j: &RevoluteJoint, states: &[BodyState]) -> [u32; 3] {
    let flag = u32::from(j.in_tree);
    if !j.enabled {
        return [0, 0, flag];
    }
    let end = |s: u32| if is_moving(states, s) { s } else { 0 };
    [end(j.state_a), end(j.state_b), flag]
}

/// The 2×3 block `J_ji` (rows 0 and 1 of a 3×3) of a joint on one body,
/// with `side` ±1 and the body's axis masks (`lin`, `ang`: 1 or 0).
#[inline(always)]
fn jacobian(side: f64, r: Vec2, lin: f64, ang: f64) -> Matrix3 {
    let r = wide(r);
    let s_l = side * lin;
    let s_a = side * ang;
    Matrix3::from_cols(
        Vec3::new(s_l, 0.0, 0.0),
        Vec3::new(0.0, s_l, 0.0),
        Vec3::new(-s_a * r.y, s_a * r.x, 0.0),
    )
}

/// Mass matrix and axis masks of a moving body: `(diag(m, m, I), lin, ang)`
/// with placeholder 1 on an axis it cannot move along.
#[inline(always)]
fn body_mass(st: &BodyState) -> (Matrix3, f64, f64) {
    let (m, lin) = if st.inv_mass > 0.0 {
        (1.0 / to_f64(st.inv_mass), 1.0)
    } else {
        (1.0, 0.0)
    };
    let (i, ang) = if st.inv_inertia > 0.0 {
        (1.0 / to_f64(st.inv_inertia), 1.0)
    } else {
        (1.0, 0.0)
    };
    (Matrix3::from_diagonal(Vec3::new(m, m, i)), lin, ang)
}

/// Widens a vector to f64.
#[inline(always)]
fn wide(v: Vec2) -> DVec2 {
    DVec2::new(to_f64(v.x), to_f64(v.y))
}

/// Relative size below which a pivot's determinant counts as zero.
const PIVOT_TOLERANCE: f64 = 16.0 * f64::EPSILON;

/// `D⁻¹` of a definite pivot; zero when it is singular or not finite (the
/// node then takes no impulse this iteration).
#[inline(always)]
fn pivot_inverse(d: &Matrix3) -> Matrix3 {
    let det = d.determinant();
    let scale = (d.x_axis.x * d.y_axis.y * d.z_axis.z).abs();
    if !det.is_finite() || det.abs() <= PIVOT_TOLERANCE * scale || det == 0.0 {
        return Matrix3::ZERO;
    }
    d.inverse()
}

impl JointForest {
    /// Number of joints whose point rows the last build put in a tree.
    pub fn tree_joint_count(&self) -> usize {
        self.tree_joints.len()
    }

    /// Finds the joint forest among the enabled joints and marks its joints
    /// (`in_tree`). With `enabled` false every joint stays iterative.
    pub fn build(&mut self, joints: &mut [RevoluteJoint], states: &[BodyState], enabled: bool) {
        self.pairs.clear();
        for j in joints.iter() {
            self.pairs.push(moving_pair(j, states));
        }
        self.update(joints, states.len(), enabled);
    }

    /// Prepares every enabled joint and finds the forest in the same pass
    /// over the joints (the batch's `prepare`).
    pub fn prepare(&mut self, joints: &mut [RevoluteJoint], ctx: &StepContext, bodies: &BodySet) {
        self.pairs.clear();
        for j in joints.iter_mut() {
            if j.enabled {
                j.prepare(ctx, bodies);
            }
            self.pairs.push(moving_pair(j, &bodies.states));
        }
        self.update(joints, bodies.states.len(), ctx.direct_joints);
    }

    /// Rebuilds the forest when the joints' moving ends changed since the
    /// last build (joints created, destroyed, enabled or disabled, bodies
    /// woken, put to sleep or re-indexed); otherwise keeps it.
    fn update(&mut self, joints: &mut [RevoluteJoint], n: usize, enabled: bool) {
        if enabled == self.built_enabled && self.pairs == self.built_pairs {
            return;
        }
        self.rebuild(joints, n, enabled);
        self.built_enabled = enabled;
        self.built_pairs.clone_from(&self.pairs);
        for (pair, j) in self.built_pairs.iter_mut().zip(joints.iter()) {
            pair[2] = u32::from(j.in_tree);
        }
    }

    fn rebuild(&mut self, joints: &mut [RevoluteJoint], n: usize, enabled: bool) {
        self.nodes.clear();
        self.trees.clear();
        self.tree_joints.clear();
        for j in joints.iter_mut() {
            j.in_tree = false;
        }
        if !enabled || joints.is_empty() {
            return;
        }
        self.union.clear();
        self.union.extend(0..n as u32);
        self.adjacency_start.clear();
        self.adjacency_start.resize(n + 1, 0);
        // Pass 1: components of moving bodies; mark those with a loop.
        self.cyclic.clear();
        self.cyclic.resize(n, false);
        for &[a, b, _] in &self.pairs {
            if a == 0 || b == 0 {
                continue;
            }
            match union(&mut self.union, a, b) {
                None => {
                    let root = find(&mut self.union, a);
                    self.cyclic[root as usize] = true;
                }
                Some((root, absorbed)) => {
                    self.cyclic[root as usize] |= self.cyclic[absorbed as usize];
                }
            }
        }
        // Pass 2: the joints of loop-free components form the forest.
        for (i, &[a, b, _]) in self.pairs.iter().enumerate() {
            if a == 0 && b == 0 {
                continue;
            }
            let root = find(&mut self.union, if a != 0 { a } else { b });
            if self.cyclic[root as usize] {
                continue;
            }
            joints[i].in_tree = true;
            self.tree_joints.push(i as u32);
            for s in [a, b] {
                if s != 0 {
                    self.adjacency_start[s as usize + 1] += 1;
                }
            }
        }
        for s in 0..n {
            self.adjacency_start[s + 1] += self.adjacency_start[s];
        }
        self.adjacency.clear();
        self.adjacency.resize(self.adjacency_start[n] as usize, 0);
        {
            let mut fill: Vec<u32> = self.adjacency_start[..n].to_vec();
            for &i in &self.tree_joints {
                for &s in &self.pairs[i as usize][..2] {
                    if s != 0 {
                        self.adjacency[fill[s as usize] as usize] = i;
                        fill[s as usize] += 1;
                    }
                }
            }
        }
        self.visited.clear();
        self.visited.resize(n, false);
        for t in 0..self.tree_joints.len() {
            let [a, b, _] = self.pairs[self.tree_joints[t] as usize];
            for root in [a, b] {
                if root != 0 && !self.visited[root as usize] {
                    self.grow(root);
                }
            }
        }
        let count = self.nodes.len();
        self.scratch.resize(count, NodeScratch::ZERO);
    }

    /// Breadth-first from `root`, appending nodes parents first.
    fn grow(&mut self, root: u32) {
        self.visited[root as usize] = true;
        let mut next = self.nodes.len();
        self.trees.push(next as u32);
        self.nodes.push(Node {
            index: root,
            parent: NONE,
            is_joint: false,
            side: 1.0,
        });
        while next < self.nodes.len() {
            let node = self.nodes[next];
            let body_node = next as u32;
            next += 1;
            if node.is_joint {
                continue;
            }
            let parent_joint = if node.parent == NONE {
                NONE
            } else {
                self.nodes[node.parent as usize].index
            };
            let s = node.index;
            let (lo, hi) = (
                self.adjacency_start[s as usize] as usize,
                self.adjacency_start[s as usize + 1] as usize,
            );
            for k in lo..hi {
                let ji = self.adjacency[k];
                if ji == parent_joint {
                    continue;
                }
                let [a, b, _] = self.pairs[ji as usize];
                let (side, other, other_side) = if b == s {
                    (1.0, a, -1.0)
                } else {
                    (-1.0, b, 1.0)
                };
                let joint_node = self.nodes.len() as u32;
                self.nodes.push(Node {
                    index: ji,
                    parent: body_node,
                    is_joint: true,
                    side,
                });
                if other != 0 && !self.visited[other as usize] {
                    self.visited[other as usize] = true;
                    self.nodes.push(Node {
                        index: other,
                        parent: joint_node,
                        is_joint: false,
                        side: other_side,
                    });
                }
            }
        }
    }

    /// One exact solve of every tree's point rows (see the module docs):
    /// with `use_bias` the soft rows with position feedback, without it the
    /// relax rows.
    pub fn solve(
        &mut self,
        ctx: &StepContext,
        joints: &mut [RevoluteJoint],
        states: &mut [BodyState],
        use_bias: bool,
    ) {
        self.solve_on(ctx, joints, states, use_bias, &Team::serial());
    }

    /// [`JointForest::solve`] with the trees spread over the step's team.
    /// Each tree is solved on a copy of its own bodies' states and joints'
    /// impulses (its nodes' scratch), reading only fixed ends from the
    /// shared states; the copies are written back in node order afterwards.
    /// Trees share no moving body, so the result is the same for any number
    /// of threads.
    pub fn solve_on(
        &mut self,
        ctx: &StepContext,
        joints: &mut [RevoluteJoint],
        states: &mut [BodyState],
        use_bias: bool,
        team: &Team,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let softness = ctx.direct_joint_softness;
        let params = TreeParams {
            softness,
            compliance: if softness.mass_scale > 0.0 {
                to_f64(softness.impulse_scale) / to_f64(softness.mass_scale)
            } else {
                0.0
            },
            h: to_f64(ctx.h),
            max_correction_speed: ctx.direct_joint_max_correction_speed,
            use_bias,
        };
        for (node, sc) in self.nodes.iter().zip(self.scratch.iter_mut()) {
            if node.is_joint {
                sc.impulse = joints[node.index as usize].point.impulse;
            } else {
                sc.state = states[node.index as usize];
            }
        }
        {
            let (nodes, joints, states) = (&self.nodes[..], &*joints, &*states);
            let mut rest = &mut self.scratch[..];
            let bounds = &self.trees;
            let split = bounds.iter().enumerate().map(move |(t, &start)| {
                let end = bounds.get(t + 1).map_or(nodes.len(), |&e| e as usize);
                let (tree, tail) = std::mem::take(&mut rest).split_at_mut(end - start as usize);
                rest = tail;
                (start as usize, tree)
            });
            if team.threads() == 1 {
                // Tree by tree, without collecting the split.
                for (start, tree) in split {
                    solve_tree(nodes, start, tree, joints, states, &params);
                }
            } else {
                let mut trees: Vec<_> = split.collect();
                let per_block = trees.len().div_ceil(4 * team.threads()).max(1);
                team.for_each_chunk_mut(&mut trees, per_block, |_, block| {
                    for (start, tree) in block.iter_mut() {
                        solve_tree(nodes, *start, tree, joints, states, &params);
                    }
                });
            }
        }
        for (node, sc) in self.nodes.iter().zip(&self.scratch) {
            if node.is_joint {
                joints[node.index as usize].point.impulse = sc.impulse;
            } else {
                let st = &mut states[node.index as usize];
                st.v = sc.state.v;
                st.w = sc.state.w;
            }
        }
    }
}

/// The step constants of one tree solve.
struct TreeParams {
    softness: janus2d_core::softness::Softness,
    /// `Γ / K = impulse_scale / mass_scale`.
    compliance: f64,
    /// Substep, s.
    h: f64,
    /// Largest correction speed, m/s.
    max_correction_speed: Real,
    use_bias: bool,
}

/// The body nodes at ends a and b of joint node `k` (`NONE` for a fixed
/// end), as tree-local indices.
#[inline(always)]
fn ends(nodes: &[Node], tree: &[NodeScratch], start: usize, k: usize) -> (u32, u32) {
    let parent = nodes[start + k].parent - start as u32;
    let child = tree[k].child;
    if nodes[start + k].side > 0.0 {
        (child, parent)
    } else {
        (parent, child)
    }
}

/// `Ĩ⁻¹ − I⁻¹` of tree-local body node `body` (state `st`): how much the
/// geometric stiffness term lowers its inverse inertia (≤ 0).
#[inline(always)]
fn inertia_change(tree: &[NodeScratch], st: &BodyState, body: u32) -> Real {
    if body == NONE || st.inv_inertia <= 0.0 {
        return 0.0;
    }
    let g = tree[body as usize].geometric;
    if g == 0.0 {
        return 0.0;
    }
    let inv = to_f64(st.inv_inertia);
    from_f64(1.0 / (1.0 / inv + g) - inv)
}

/// The state of end `body` (tree-local, `NONE` for a fixed end, then read
/// from the shared states at `index`).
#[inline(always)]
fn end_state(tree: &[NodeScratch], states: &[BodyState], body: u32, index: u32) -> BodyState {
    if body == NONE {
        states[index as usize]
    } else {
        tree[body as usize].state
    }
}

/// Joint node `k`'s joint and the states of its ends a and b (tree copies,
/// or the shared states for a fixed end).
#[inline(always)]
fn joint_states<'j>(
    nodes: &[Node],
    start: usize,
    tree: &[NodeScratch],
    joints: &'j [RevoluteJoint],
    states: &[BodyState],
    k: usize,
) -> (&'j RevoluteJoint, BodyState, BodyState) {
    let j = &joints[nodes[start + k].index as usize];
    let (body_a, body_b) = ends(nodes, tree, start, k);
    (
        j,
        end_state(tree, states, body_a, j.state_a),
        end_state(tree, states, body_b, j.state_b),
    )
}

/// One tree's exact solve on its nodes `start..start + tree.len()`: the
/// arithmetic of the module docs on the tree's scratch (its bodies' states,
/// its joints' impulses), reading fixed ends from `states`.
fn solve_tree(
    nodes: &[Node],
    start: usize,
    tree: &mut [NodeScratch],
    joints: &[RevoluteJoint],
    states: &[BodyState],
    params: &TreeParams,
) {
    let n = tree.len();
    let node_at = |k: usize| nodes[start + k];
    let local = |k: u32| k as usize - start;
    let TreeParams {
        softness,
        compliance,
        h,
        max_correction_speed,
        use_bias,
    } = *params;
    // Arms of every joint and the geometric stiffness each body takes from
    // its joints (one from the parent joint, one per child joint).
    for sc in tree.iter_mut() {
        sc.geometric = 0.0;
        sc.child = NONE;
    }
    for k in 0..n {
        let node = node_at(k);
        if node.is_joint || node.parent == NONE {
            continue;
        }
        tree[local(node.parent)].child = k as u32;
    }
    for k in 0..n {
        let node = node_at(k);
        if !node.is_joint {
            continue;
        }
        let (j, sa, sb) = joint_states(nodes, start, tree, joints, states, k);
        let (r_a, r_b, _) = j.point.arms(&sa, &sb);
        tree[k].arms = (r_a, r_b);
        let lambda = wide(tree[k].impulse);
        tree[local(node.parent)].geometric += geometric_stiffness(h, lambda, (r_a, r_b), node.side);
    }
    for k in 0..n {
        let node = node_at(k);
        if node.is_joint || node.parent == NONE {
            continue;
        }
        let p = local(node.parent);
        let lambda = wide(tree[p].impulse);
        let arms = tree[p].arms;
        tree[k].geometric += geometric_stiffness(h, lambda, arms, node.side);
    }
    // Ĩ = max(I, K_g / GEOMETRIC_RATIO): only the inertia the limit needs
    // is added.
    for sc in tree.iter_mut().zip(0..n) {
        let (sc, k) = sc;
        if node_at(k).is_joint {
            continue;
        }
        let (m, _, _) = body_mass(&sc.state);
        sc.geometric = (sc.geometric / GEOMETRIC_RATIO - m.z_axis.z).max(0.0);
    }
    if use_bias {
        // The warm start applied the kept impulses through the bodies' own
        // inertia; re-weight their torque to the solve's inertia.
        for k in 0..n {
            if !node_at(k).is_joint {
                continue;
            }
            let impulse = tree[k].impulse;
            let (r_a, r_b) = tree[k].arms;
            let (body_a, body_b) = ends(nodes, tree, start, k);
            if body_a != NONE {
                let st = tree[body_a as usize].state;
                let wa = inertia_change(tree, &st, body_a);
                tree[body_a as usize].state.w -= wa * cross(r_a, impulse);
            }
            if body_b != NONE {
                let st = tree[body_b as usize].state;
                let wb = inertia_change(tree, &st, body_b);
                tree[body_b as usize].state.w += wb * cross(r_b, impulse);
            }
        }
    }
    // Joint rows: right-hand sides and pivots.
    for k in 0..n {
        let node = node_at(k);
        if !node.is_joint {
            continue;
        }
        let (j, sa, sb) = joint_states(nodes, start, tree, joints, states, k);
        let (r_a, r_b, c) = j.point.arms(&sa, &sb);
        let c_dot = (sb.v + cross_sv(sb.w, r_b)) - (sa.v + cross_sv(sa.w, r_a));
        let (k11, k12, k22) = crate::parts::PointPart::effective_mass(&sa, &sb, r_a, r_b);
        let (k11, k12, k22) = (to_f64(k11), to_f64(k12), to_f64(k22));
        let gamma = Matrix3::from_cols(
            Vec3::new(k11, k12, 0.0) * compliance,
            Vec3::new(k12, k22, 0.0) * compliance,
            Vec3::new(0.0, 0.0, 1.0),
        );
        let rhs = if use_bias {
            let bias = clamp_length(softness.bias_rate * c, max_correction_speed);
            let lambda = wide(tree[k].impulse);
            let held = DVec2::new(
                k11 * lambda.x + k12 * lambda.y,
                k12 * lambda.x + k22 * lambda.y,
            ) * compliance;
            -(wide(c_dot + bias) + held)
        } else {
            -wide(c_dot)
        };
        tree[k].d = -gamma;
        tree[k].b = Vec3::new(rhs.x, rhs.y, 0.0);
    }
    // Body pivots: mass and inertia plus the geometric stiffness.
    for k in 0..n {
        if node_at(k).is_joint {
            continue;
        }
        let (mut m, _, ang) = body_mass(&tree[k].state);
        m.z_axis.z += ang * tree[k].geometric;
        tree[k].d = m;
        tree[k].b = Vec3::ZERO;
    }
    // Eliminate leaves first.
    for k in (0..n).rev() {
        let node = node_at(k);
        let d_inv = pivot_inverse(&tree[k].d);
        tree[k].d = d_inv;
        if node.parent == NONE {
            continue;
        }
        let p = local(node.parent);
        // E_k = H_parent,k.
        let e = if node.is_joint {
            let (_, lin, ang) = body_mass(&tree[p].state);
            let (r_a, r_b) = tree[k].arms;
            let r = if node.side > 0.0 { r_b } else { r_a };
            jacobian(node.side, r, lin, ang).transpose()
        } else {
            let (_, lin, ang) = body_mass(&tree[k].state);
            let (r_a, r_b) = tree[p].arms;
            let r = if node.side > 0.0 { r_b } else { r_a };
            jacobian(node.side, r, lin, ang)
        };
        let l = e * d_inv;
        tree[k].l = l;
        tree[p].d -= l * e.transpose();
        let b_k = tree[k].b;
        tree[p].b -= l * b_k;
    }
    // Back substitution, parents first.
    for k in 0..n {
        let node = node_at(k);
        let mut x = tree[k].d * tree[k].b;
        if node.parent != NONE {
            x -= tree[k].l.transpose() * tree[local(node.parent)].b;
        }
        tree[k].b = x;
    }
    // Apply Δλ = −μ through each joint (equal and opposite at its anchors),
    // so linear momentum holds to rounding whatever the pivots' size; the
    // bodies' own Δv is the same change up to the solve's precision. The
    // angular part acts with the inertia the solve used (the body's plus
    // its geometric stiffness term). Fixed ends do not move.
    for k in 0..n {
        if !node_at(k).is_joint {
            continue;
        }
        let x = tree[k].b;
        let impulse = -Vec2::new(from_f64(x.x), from_f64(x.y));
        tree[k].impulse += impulse;
        let (r_a, r_b) = tree[k].arms;
        let (body_a, body_b) = ends(nodes, tree, start, k);
        if body_a != NONE {
            let sa = tree[body_a as usize].state;
            let i_a = sa.inv_inertia + inertia_change(tree, &sa, body_a);
            let st = &mut tree[body_a as usize].state;
            st.v -= sa.inv_mass * impulse;
            st.w -= i_a * cross(r_a, impulse);
        }
        if body_b != NONE {
            let sb = tree[body_b as usize].state;
            let i_b = sb.inv_inertia + inertia_change(tree, &sb, body_b);
            let st = &mut tree[body_b as usize].state;
            st.v += sb.inv_mass * impulse;
            st.w += i_b * cross(r_b, impulse);
        }
    }
}

/// The geometric stiffness term of a joint's impulse `λ` (on body b; −λ on
/// a) on its body on `side` (+1: b, −1: a) over a substep of `h`:
/// `h λ · r_b` for b, `−h λ · r_a` for a, where positive (a restoring
/// torque: tension along the arm); zero otherwise.
#[inline(always)]
fn geometric_stiffness(h: f64, lambda: DVec2, arms: (Vec2, Vec2), side: f64) -> f64 {
    let r = if side > 0.0 { arms.1 } else { arms.0 };
    (h * side * lambda.dot(wide(r))).max(0.0)
}

/// The revolute joints of a world and their forest, driven by the solver as
/// one batch: the iterative rows in the sweep with the other constraints
/// (before the contacts), the direct tree solve in the late pass after
/// every batch (so the tree's joints have the last word).
pub struct RevoluteBatch<'a> {
    /// The joints, in storage order.
    pub joints: &'a mut Vec<RevoluteJoint>,
    /// The forest found at `prepare`.
    pub forest: &'a mut JointForest,
}

impl ConstraintBatch for RevoluteBatch<'_> {
    fn count(&self) -> usize {
        self.joints.len()
    }
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        self.forest.prepare(self.joints, ctx, bodies);
    }
    fn warm_start(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        self.joints.warm_start(ctx, states);
    }
    fn solve(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
    ) {
        self.joints.solve(ctx, states, use_bias, reverse);
    }
    fn solve_late(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        self.forest.solve(ctx, self.joints, states, use_bias);
    }
    fn solve_late_on(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        team: &Team,
    ) {
        self.forest
            .solve_on(ctx, self.joints, states, use_bias, team);
    }
    fn apply_restitution(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        self.joints.apply_restitution(ctx, states);
    }
    fn store_impulses(&mut self) {
        self.joints.store_impulses();
    }
}
