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
//! **Layout.** Each tree keeps its bodies and its joints breadth-first from
//! a root body, in two flat arrays; a joint knows its parent body and its
//! child body (none for a fixed end). Going through the joints backwards,
//! joint `k` first folds in its child body `c` (whose own joints all come
//! after `k`, so its pivot is complete), then is folded into its parent
//! `p`; back substitution goes forwards:
//!
//! ```text
//!  eliminate, k last to first:  D_k = −Γ_k − J_kc D_c⁻¹ J_kcᵀ     b_k −= J_kc D_c⁻¹ b_c
//!                               D_p −= J_kpᵀ D_k⁻¹ J_kp           b_p −= J_kpᵀ D_k⁻¹ b_k
//!  substitute, root first:      x_k = D_k⁻¹ (b_k − J_kp x_p)      x_c = D_c⁻¹ (b_c − J_kcᵀ x_k)
//! ```
//!
//! Body pivots are symmetric 3×3 and stay positive definite, joint pivots
//! symmetric 2×2 and negative definite, so both are inverted by cofactors
//! without pivoting; `J_ji = ±[I | perp(r)]`, so its products with a pivot
//! are written out (about a third of the work of general 3×3 blocks). A
//! leaf body (no joint below it) keeps the pivot `diag(m, m, Ĩ)`, whose
//! inverse is its inverse mass and inertia, and its `b` stays zero. The
//! elimination runs in f64
//! whatever [`Real`] is: the pivots of a 670:1 chain cost about four digits,
//! which f32 does not have to spare (measured: 3e-3 relative residual in
//! f32 arithmetic at a mass spread of 1e4, 1e-11 in f64), and scalar f64 costs
//! the same as f32 here. A body that cannot
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

use glam::{DVec2, DVec3};
use janus2d_core::body::BodySet;
use janus2d_core::body::BodyState;
use janus2d_core::constraint::{Constraint, ConstraintBatch, StepContext};
use janus2d_core::math::{Real, Vec2, cross, cross_sv, from_f64, to_f64};
use janus2d_core::parallel::Team;
use janus2d_core::union_find::{find, union};

use crate::parts::{PointPart, clamp_length};
use crate::revolute::RevoluteJoint;

const NONE: u32 = u32::MAX;

/// Largest ratio `K_g / Ĩ` of a body's geometric stiffness term to the
/// inertia the tree solve gives it (see the module docs): the explicit part
/// of a taut chain's zig-zag mode is stable below 4; 2.5 leaves a margin.
const GEOMETRIC_RATIO: f64 = 2.5;

/// A joint of a tree. A tree's joints are in breadth-first order from its
/// root body: a joint comes after its parent body's own parent joint and
/// before its child body's other joints, so going through them backwards
/// eliminates every subtree before the joint above it.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct TreeJoint {
    /// Its index in the joint slice.
    index: u32,
    /// Its parent body, tree-local (the root is body 0).
    parent: u32,
    /// Its child body, tree-local; `NONE` where the other end is fixed.
    child: u32,
    /// The parent body's side of the joint: +1 where it is the joint's
    /// body b, −1 where it is body a (the other end is on the other side).
    side: f64,
}

/// Where a tree's bodies and joints start in the forest's arrays.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct TreeStart {
    bodies: u32,
    joints: u32,
}

/// A symmetric 3×3 matrix over `(v_x, v_y, ω)`: a body's pivot.
#[derive(Clone, Copy, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Sym3 {
    xx: f64,
    xy: f64,
    xw: f64,
    yy: f64,
    yw: f64,
    ww: f64,
}

impl Sym3 {
    const ZERO: Sym3 = Sym3 {
        xx: 0.0,
        xy: 0.0,
        xw: 0.0,
        yy: 0.0,
        yw: 0.0,
        ww: 0.0,
    };

    #[inline(always)]
    fn diagonal(m: f64, i: f64) -> Sym3 {
        Sym3 {
            xx: m,
            yy: m,
            ww: i,
            ..Sym3::ZERO
        }
    }

    #[inline(always)]
    fn mul(&self, v: DVec3) -> DVec3 {
        DVec3::new(
            self.xx * v.x + self.xy * v.y + self.xw * v.z,
            self.xy * v.x + self.yy * v.y + self.yw * v.z,
            self.xw * v.x + self.yw * v.y + self.ww * v.z,
        )
    }

    #[inline(always)]
    fn sub_assign(&mut self, o: &Sym3) {
        self.xx -= o.xx;
        self.xy -= o.xy;
        self.xw -= o.xw;
        self.yy -= o.yy;
        self.yw -= o.yw;
        self.ww -= o.ww;
    }

    /// The inverse of a definite pivot (cofactors over the determinant);
    /// zero when it is singular or not finite (its node then takes no
    /// impulse this solve).
    #[inline(always)]
    fn inverse(&self) -> Sym3 {
        let c_xx = self.yy * self.ww - self.yw * self.yw;
        let c_xy = self.xw * self.yw - self.xy * self.ww;
        let c_xw = self.xy * self.yw - self.xw * self.yy;
        let det = self.xx * c_xx + self.xy * c_xy + self.xw * c_xw;
        let scale = (self.xx * self.yy * self.ww).abs();
        if !det.is_finite() || det.abs() <= PIVOT_TOLERANCE * scale || det == 0.0 {
            return Sym3::ZERO;
        }
        let inv = 1.0 / det;
        Sym3 {
            xx: c_xx * inv,
            xy: c_xy * inv,
            xw: c_xw * inv,
            yy: (self.xx * self.ww - self.xw * self.xw) * inv,
            yw: (self.xy * self.xw - self.xx * self.yw) * inv,
            ww: (self.xx * self.yy - self.xy * self.xy) * inv,
        }
    }
}

/// A symmetric 2×2 matrix over a joint's two rows: a joint's pivot.
#[derive(Clone, Copy, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Sym2 {
    xx: f64,
    xy: f64,
    yy: f64,
}

impl Sym2 {
    const ZERO: Sym2 = Sym2 {
        xx: 0.0,
        xy: 0.0,
        yy: 0.0,
    };

    #[inline(always)]
    fn mul(&self, v: DVec2) -> DVec2 {
        DVec2::new(self.xx * v.x + self.xy * v.y, self.xy * v.x + self.yy * v.y)
    }

    /// As [`Sym3::inverse`].
    #[inline(always)]
    fn inverse(&self) -> Sym2 {
        let det = self.xx * self.yy - self.xy * self.xy;
        let scale = (self.xx * self.yy).abs();
        if !det.is_finite() || det.abs() <= PIVOT_TOLERANCE * scale || det == 0.0 {
            return Sym2::ZERO;
        }
        let inv = 1.0 / det;
        Sym2 {
            xx: self.yy * inv,
            xy: -self.xy * inv,
            yy: self.xx * inv,
        }
    }
}

/// A joint's 2×3 block on one body without its sign (`J_ji = ±Ĵ`):
/// `Ĵ = [l 0 p_x; 0 l p_y]`, `(p_x, p_y) = a (−r.y, r.x)`, with the body's
/// axis masks `l`, `a` (1, or 0 on an axis it cannot move along).
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Jacobian {
    lin: f64,
    px: f64,
    py: f64,
}

impl Jacobian {
    const ZERO: Jacobian = Jacobian {
        lin: 0.0,
        px: 0.0,
        py: 0.0,
    };

    #[inline(always)]
    fn new(r: Vec2, body: &BodyScratch) -> Jacobian {
        Jacobian {
            lin: body.lin,
            px: -body.ang * to_f64(r.y),
            py: body.ang * to_f64(r.x),
        }
    }

    /// `Ĵ v`.
    #[inline(always)]
    fn mul(&self, v: DVec3) -> DVec2 {
        DVec2::new(
            self.lin * v.x + self.px * v.z,
            self.lin * v.y + self.py * v.z,
        )
    }

    /// `Ĵᵀ y`.
    #[inline(always)]
    fn mul_t(&self, y: DVec2) -> DVec3 {
        DVec3::new(
            self.lin * y.x,
            self.lin * y.y,
            self.px * y.x + self.py * y.y,
        )
    }

    /// `Ĵ S Ĵᵀ` (the sign cancels).
    #[inline(always)]
    fn sandwich3(&self, s: &Sym3) -> Sym2 {
        let (l, px, py) = (self.lin, self.px, self.py);
        // Rows of Ĵ S.
        let g0 = DVec3::new(
            l * s.xx + px * s.xw,
            l * s.xy + px * s.yw,
            l * s.xw + px * s.ww,
        );
        let g1y = l * s.yy + py * s.yw;
        let g1w = l * s.yw + py * s.ww;
        Sym2 {
            xx: g0.x * l + g0.z * px,
            xy: g0.y * l + g0.z * py,
            yy: g1y * l + g1w * py,
        }
    }

    /// `Ĵ S Ĵᵀ` for a diagonal `S`.
    #[inline(always)]
    fn sandwich_diagonal(&self, s: &Sym3) -> Sym2 {
        let (l, px, py) = (self.lin, self.px, self.py);
        let ll = l * l * s.xx;
        Sym2 {
            xx: ll + px * px * s.ww,
            xy: px * py * s.ww,
            yy: l * l * s.yy + py * py * s.ww,
        }
    }

    /// `Ĵᵀ T Ĵ` (the sign cancels).
    #[inline(always)]
    fn sandwich2(&self, t: &Sym2) -> Sym3 {
        let (l, px, py) = (self.lin, self.px, self.py);
        let u0 = t.xx * px + t.xy * py;
        let u1 = t.xy * px + t.yy * py;
        let ll = l * l;
        Sym3 {
            xx: ll * t.xx,
            xy: ll * t.xy,
            xw: l * u0,
            yy: ll * t.yy,
            yw: l * u1,
            ww: px * u0 + py * u1,
        }
    }
}

/// A tree body's scratch in the tree solve.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct BodyScratch {
    /// A copy of its state while the tree is solved.
    state: BodyState,
    /// The pivot `D_k` while eliminating, then `D_k⁻¹`.
    d: Sym3,
    /// The right-hand side, then the solution.
    b: DVec3,
    /// Axis masks: 1 where the body translates (rotates), else 0.
    lin: f64,
    ang: f64,
    /// No joint of the tree has this body as its parent: its pivot stays
    /// `diag(m, m, Ĩ)`, which `d` then holds inverted from the start, and
    /// its right-hand side stays zero.
    leaf: bool,
    /// First the geometric stiffness term `K_g = h Σ max(0, ±λ · r)`, then
    /// the inertia added for it, `max(0, K_g / GEOMETRIC_RATIO − I)` (see
    /// the module docs), kg·m².
    geometric: f64,
    /// `Ĩ⁻¹ − I⁻¹` (≤ 0): how much the added inertia lowers the inverse
    /// inertia the solve's impulses act through.
    inertia_change: Real,
}

impl BodyScratch {
    const ZERO: BodyScratch = BodyScratch {
        state: BodyState::IDENTITY,
        d: Sym3::ZERO,
        b: DVec3::ZERO,
        lin: 0.0,
        ang: 0.0,
        leaf: true,
        geometric: 0.0,
        inertia_change: 0.0,
    };

    /// Turns the body by an impulse `p` at arm `r` on `side` (+1: the
    /// joint's body b) through the inertia added for the solve: the
    /// re-weighting of a torque applied through `I` to `Ĩ`.
    #[inline(always)]
    fn reweight(&mut self, side: f64, r: Vec2, p: Vec2) {
        self.state.w += (from_f64(side) * self.inertia_change) * cross(r, p);
    }

    /// Applies the impulse `p` at arm `r` on `side` (+1: the joint's body
    /// b, which takes `+p`; −1: body a, `−p`), turning through `Ĩ`.
    #[inline(always)]
    fn apply(&mut self, side: f64, r: Vec2, p: Vec2) {
        let st = &mut self.state;
        let side = from_f64(side);
        let inv_i = st.inv_inertia + self.inertia_change;
        st.v += (side * st.inv_mass) * p;
        st.w += (side * inv_i) * cross(r, p);
    }
}

impl Default for BodyScratch {
    fn default() -> Self {
        Self::ZERO
    }
}

/// A tree joint's scratch in the tree solve.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct JointScratch {
    /// The arms of its parent end and of its other end in this solve.
    r_parent: Vec2,
    r_other: Vec2,
    /// `Ĵ` on its parent body and on its child body (if any).
    jac_parent: Jacobian,
    jac_child: Jacobian,
    /// The separation `C = (x_b + r_b) − (x_a + r_a)`, m.
    c: Vec2,
    /// A copy of its accumulated point impulse, N·s.
    impulse: Vec2,
    /// The state index of its fixed end (read when it has no child body).
    fixed: u32,
    /// The pivot `D_k` while eliminating, then `D_k⁻¹`.
    d: Sym2,
    /// The right-hand side, then the solution `μ`.
    b: DVec2,
}

impl JointScratch {
    const ZERO: JointScratch = JointScratch {
        r_parent: Vec2::ZERO,
        r_other: Vec2::ZERO,
        jac_parent: Jacobian::ZERO,
        jac_child: Jacobian::ZERO,
        c: Vec2::ZERO,
        impulse: Vec2::ZERO,
        fixed: 0,
        d: Sym2::ZERO,
        b: DVec2::ZERO,
    };
}

impl Default for JointScratch {
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
    /// Per tree: its first body and first joint (a tree's bodies, and its
    /// joints, are contiguous).
    trees: Vec<TreeStart>,
    /// The trees' bodies (state indices), each tree breadth-first from its
    /// root.
    bodies: Vec<u32>,
    /// The trees' joints, in the same breadth-first order.
    joints: Vec<TreeJoint>,
    /// Per tree body and per tree joint: the solve's scratch.
    body_scratch: Vec<BodyScratch>,
    joint_scratch: Vec<JointScratch>,
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
    /// Per tree body: its parent joint (an index into the joint slice).
    parent_joint: Vec<u32>,
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

/// Widens a vector to f64.
#[inline(always)]
fn wide(v: Vec2) -> DVec2 {
    DVec2::new(to_f64(v.x), to_f64(v.y))
}

/// Relative size below which a pivot's determinant counts as zero.
const PIVOT_TOLERANCE: f64 = 16.0 * f64::EPSILON;

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
        self.trees.clear();
        self.bodies.clear();
        self.joints.clear();
        self.parent_joint.clear();
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
        self.body_scratch
            .resize(self.bodies.len(), BodyScratch::ZERO);
        self.joint_scratch
            .resize(self.joints.len(), JointScratch::ZERO);
    }

    /// Breadth-first from `root`, appending the tree's bodies and joints.
    fn grow(&mut self, root: u32) {
        self.visited[root as usize] = true;
        let first = self.bodies.len();
        self.trees.push(TreeStart {
            bodies: first as u32,
            joints: self.joints.len() as u32,
        });
        self.bodies.push(root);
        self.parent_joint.push(NONE);
        let mut next = first;
        while next < self.bodies.len() {
            let s = self.bodies[next];
            let parent_joint = self.parent_joint[next];
            let parent = (next - first) as u32;
            next += 1;
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
                let (parent_is_b, other) = if b == s { (true, a) } else { (false, b) };
                let child = if other != 0 && !self.visited[other as usize] {
                    self.visited[other as usize] = true;
                    self.bodies.push(other);
                    self.parent_joint.push(ji);
                    (self.bodies.len() - 1 - first) as u32
                } else {
                    NONE
                };
                self.joints.push(TreeJoint {
                    index: ji,
                    parent,
                    child,
                    side: if parent_is_b { 1.0 } else { -1.0 },
                });
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
    /// impulses (its scratch), reading only fixed ends from the shared
    /// states; the copies are written back in tree order afterwards.
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
        if self.trees.is_empty() {
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
        {
            let (bodies, tree_joints) = (&self.bodies[..], &self.joints[..]);
            let (joints, states) = (&*joints, &*states);
            let mut rest_bodies = &mut self.body_scratch[..];
            let mut rest_joints = &mut self.joint_scratch[..];
            let starts = &self.trees;
            let split = starts.iter().enumerate().map(move |(t, &start)| {
                let end = starts.get(t + 1).copied().unwrap_or(TreeStart {
                    bodies: bodies.len() as u32,
                    joints: tree_joints.len() as u32,
                });
                let body_range = start.bodies as usize..end.bodies as usize;
                let joint_range = start.joints as usize..end.joints as usize;
                let (body_scratch, tail) =
                    std::mem::take(&mut rest_bodies).split_at_mut(body_range.len());
                rest_bodies = tail;
                let (joint_scratch, tail) =
                    std::mem::take(&mut rest_joints).split_at_mut(joint_range.len());
                rest_joints = tail;
                Tree {
                    states: &bodies[body_range],
                    joints: &tree_joints[joint_range],
                    bodies: body_scratch,
                    rows: joint_scratch,
                }
            });
            if team.threads() == 1 {
                // Tree by tree, without collecting the split.
                for mut tree in split {
                    solve_tree(&mut tree, joints, states, &params);
                }
            } else {
                let mut trees: Vec<_> = split.collect();
                let per_block = trees.len().div_ceil(4 * team.threads()).max(1);
                team.for_each_chunk_mut(&mut trees, per_block, |_, block| {
                    for tree in block.iter_mut() {
                        solve_tree(tree, joints, states, &params);
                    }
                });
            }
        }
        for (&s, sc) in self.bodies.iter().zip(&self.body_scratch) {
            let st = &mut states[s as usize];
            st.v = sc.state.v;
            st.w = sc.state.w;
        }
        for (tj, row) in self.joints.iter().zip(&self.joint_scratch) {
            joints[tj.index as usize].point.impulse = row.impulse;
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

/// One tree's share of the forest: its topology and its scratch.
struct Tree<'a> {
    /// Its bodies' state indices, breadth-first from the root.
    states: &'a [u32],
    /// Its joints, breadth-first.
    joints: &'a [TreeJoint],
    /// Per body and per joint: the solve's scratch.
    bodies: &'a mut [BodyScratch],
    rows: &'a mut [JointScratch],
}

/// The state of tree joint `tj`'s other end: the tree's copy of its child
/// body, or the shared state `fixed` for a fixed end.
#[inline(always)]
fn other_end<'s>(
    tj: &TreeJoint,
    fixed: u32,
    bodies: &'s [BodyScratch],
    states: &'s [BodyState],
) -> &'s BodyState {
    if tj.child == NONE {
        &states[fixed as usize]
    } else {
        &bodies[tj.child as usize].state
    }
}

/// One tree's exact solve: the arithmetic of the module docs on the tree's
/// scratch (its bodies' states, its joints' impulses), reading the fixed
/// ends from `states`. Each joint is seen from its parent body: `C` and `Ċ`
/// are `side ((x_p + r_p) − (x_o + r_o))`, with `o` its other end (child or
/// fixed) and `side` +1 where the parent is the joint's body b.
fn solve_tree(
    tree: &mut Tree<'_>,
    joints: &[RevoluteJoint],
    states: &[BodyState],
    params: &TreeParams,
) {
    let TreeParams {
        softness,
        compliance,
        h,
        max_correction_speed,
        use_bias,
    } = *params;
    let Tree {
        states: indices,
        joints: topology,
        bodies,
        rows,
    } = tree;
    let (topology, bodies, rows) = (&**topology, &mut **bodies, &mut **rows);
    for (sc, &s) in bodies.iter_mut().zip(indices.iter()) {
        let st = states[s as usize];
        sc.state = st;
        sc.lin = if st.inv_mass > 0.0 { 1.0 } else { 0.0 };
        sc.ang = if st.inv_inertia > 0.0 { 1.0 } else { 0.0 };
        sc.leaf = true;
        sc.geometric = 0.0;
    }
    // Arms, separations, Jacobians and impulses of the joints, and the
    // geometric stiffness each body takes from its joints.
    for (tj, row) in topology.iter().zip(rows.iter_mut()) {
        let j = &joints[tj.index as usize];
        let side = tj.side;
        let (frame_parent, frame_other, fixed) = if side > 0.0 {
            (j.point.frame_b, j.point.frame_a, j.state_a)
        } else {
            (j.point.frame_a, j.point.frame_b, j.state_b)
        };
        row.fixed = fixed;
        let parent = &bodies[tj.parent as usize];
        let other = other_end(tj, fixed, bodies, states);
        let r_parent = parent.state.dq.rotate(frame_parent);
        let r_other = other.dq.rotate(frame_other);
        row.c = from_f64(side) * ((parent.state.dp - other.dp) + (r_parent - r_other))
            + j.point.delta_center;
        (row.r_parent, row.r_other) = (r_parent, r_other);
        row.jac_parent = Jacobian::new(r_parent, parent);
        row.impulse = j.point.impulse;
        let lambda = wide(row.impulse);
        let parent = &mut bodies[tj.parent as usize];
        parent.leaf = false;
        parent.geometric += geometric_stiffness(h, lambda, r_parent, side);
        if tj.child != NONE {
            let child = &mut bodies[tj.child as usize];
            row.jac_child = Jacobian::new(r_other, child);
            child.geometric += geometric_stiffness(h, lambda, r_other, -side);
        }
    }
    // Ĩ = max(I, K_g / GEOMETRIC_RATIO): only the inertia the limit needs
    // is added. Body pivots start as diag(m, m, Ĩ), placeholder 1 on an
    // axis the body cannot move along; a leaf's is inverted at once.
    for sc in bodies.iter_mut() {
        let st = &sc.state;
        let (inv_m, inv_i) = (to_f64(st.inv_mass), to_f64(st.inv_inertia));
        let (mut added, mut inv_i_tilde) = (0.0, inv_i);
        // K_g / GEOMETRIC_RATIO > I, without dividing where it is not.
        if sc.ang > 0.0 && sc.geometric * inv_i > GEOMETRIC_RATIO {
            added = (sc.geometric / GEOMETRIC_RATIO - 1.0 / inv_i).max(0.0);
            if added > 0.0 {
                inv_i_tilde = 1.0 / (1.0 / inv_i + added);
            }
        }
        sc.inertia_change = from_f64(inv_i_tilde - inv_i);
        sc.geometric = added;
        sc.d = if sc.leaf {
            Sym3::diagonal(
                if sc.lin > 0.0 { inv_m } else { 1.0 },
                if sc.ang > 0.0 { inv_i_tilde } else { 1.0 },
            )
        } else {
            Sym3::diagonal(
                if sc.lin > 0.0 { 1.0 / inv_m } else { 1.0 },
                if sc.ang > 0.0 {
                    1.0 / inv_i + added
                } else {
                    1.0
                },
            )
        };
        sc.b = DVec3::ZERO;
    }
    if use_bias {
        // The warm start applied the kept impulses through the bodies' own
        // inertia; re-weight their torque to the solve's inertia.
        for (tj, row) in topology.iter().zip(rows.iter()) {
            bodies[tj.parent as usize].reweight(tj.side, row.r_parent, row.impulse);
            if tj.child != NONE {
                bodies[tj.child as usize].reweight(-tj.side, row.r_other, row.impulse);
            }
        }
    }
    // Leaves first: each joint's row and pivot, its child body's subtree
    // folded in (that body's pivot is complete: its other joints come
    // later), then the joint folded into its parent body.
    for (tj, row) in topology.iter().zip(rows.iter_mut()).rev() {
        let side = tj.side;
        let (r_parent, r_other) = (row.r_parent, row.r_other);
        let parent = &bodies[tj.parent as usize].state;
        let other = other_end(tj, row.fixed, bodies, states);
        let c_dot = from_f64(side)
            * ((parent.v + cross_sv(parent.w, r_parent)) - (other.v + cross_sv(other.w, r_other)));
        let (k11, k12, k22) = PointPart::effective_mass(parent, other, r_parent, r_other);
        let (k11, k12, k22) = (to_f64(k11), to_f64(k12), to_f64(k22));
        let rhs = if use_bias {
            let bias = clamp_length(softness.bias_rate * row.c, max_correction_speed);
            let lambda = wide(row.impulse);
            let held = DVec2::new(
                k11 * lambda.x + k12 * lambda.y,
                k12 * lambda.x + k22 * lambda.y,
            ) * compliance;
            -(wide(c_dot + bias) + held)
        } else {
            -wide(c_dot)
        };
        // D_k = −Γ, Γ = K / a2.
        let mut d = Sym2 {
            xx: -(k11 * compliance),
            xy: -(k12 * compliance),
            yy: -(k22 * compliance),
        };
        let mut b = rhs;
        if tj.child != NONE {
            // D_k −= J D_c⁻¹ Jᵀ,  b_k −= J D_c⁻¹ b_c  (J = −side Ĵ); a
            // leaf's D_c⁻¹ is diagonal and its b_c zero.
            let child = &mut bodies[tj.child as usize];
            let jac = row.jac_child;
            let s = if child.leaf {
                jac.sandwich_diagonal(&child.d)
            } else {
                child.d = child.d.inverse();
                b += side * jac.mul(child.d.mul(child.b));
                jac.sandwich3(&child.d)
            };
            d.xx -= s.xx;
            d.xy -= s.xy;
            d.yy -= s.yy;
        }
        let t = d.inverse();
        row.d = t;
        row.b = b;
        // D_p −= Jᵀ D_k⁻¹ J,  b_p −= Jᵀ D_k⁻¹ b_k  (J = side Ĵ).
        let parent = &mut bodies[tj.parent as usize];
        let jac = row.jac_parent;
        parent.d.sub_assign(&jac.sandwich2(&t));
        parent.b -= side * jac.mul_t(t.mul(b));
    }
    // Back substitution, root first: x_k = D_k⁻¹ (b_k − E_kᵀ x_parent).
    // Each joint's Δλ = −μ is applied as soon as it is known, equal and
    // opposite at its anchors, so linear momentum holds to rounding
    // whatever the pivots' size; the bodies' own Δv is the same change up
    // to the solve's precision. The angular part acts with the inertia the
    // solve used (the body's plus its geometric stiffness term). Fixed ends
    // do not move.
    let root = &mut bodies[0];
    if !root.leaf {
        root.d = root.d.inverse();
    }
    root.b = root.d.mul(root.b);
    for (tj, row) in topology.iter().zip(rows.iter_mut()) {
        let side = tj.side;
        let parent = &mut bodies[tj.parent as usize];
        let x = row.d.mul(row.b - side * row.jac_parent.mul(parent.b));
        row.b = x;
        let impulse = -Vec2::new(from_f64(x.x), from_f64(x.y));
        row.impulse += impulse;
        parent.apply(side, row.r_parent, impulse);
        if tj.child != NONE {
            let child = &mut bodies[tj.child as usize];
            if !child.leaf {
                // A leaf's solution is not needed: no joint below it.
                child.b = child.d.mul(child.b + side * row.jac_child.mul_t(x));
            }
            child.apply(-side, row.r_other, impulse);
        }
    }
}

/// The geometric stiffness term of a joint's impulse `λ` (on body b; −λ on
/// a) on its body on `side` (+1: b, −1: a) with arm `r` over a substep of
/// `h`: `h λ · r_b` for b, `−h λ · r_a` for a, where positive (a restoring
/// torque: tension along the arm); zero otherwise.
#[inline(always)]
fn geometric_stiffness(h: f64, lambda: DVec2, r: Vec2, side: f64) -> f64 {
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
