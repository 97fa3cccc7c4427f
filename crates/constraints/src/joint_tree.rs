//! Direct solve of the joints' equality rows where the joints form a tree:
//! a revolute joint's point rows (2), a rigid weld's point and angle rows
//! (3).
//!
//! Gauss–Seidel moves information one joint per iteration and builds a soft
//! joint's spring on the *light* body's effective mass, so a heavy load on a
//! chain of light links (the "ball and chain", 670:1) stretches every joint
//! by about `F K / ω²`. Where the joints form a tree, the point rows of the
//! whole tree (and the angle rows of its rigid welds) can instead be
//! solved exactly in time linear in its size
//! (the idea of Baraff, *Linear-time dynamics using Lagrange multipliers*,
//! 1996), and an exact solve stays stable at any stiffness.
//!
//! # Derivation
//!
//! Unknowns: the velocity change `Δv_i = (Δv_x, Δv_y, Δω)` of every moving
//! body in the tree and the impulse change `Δλ_j` (`n_j` rows: 2 or 3) of
//! every joint. With `J_ji` the `n_j`×3 block of joint `j` on body `i`
//!
//! ```text
//! J_jb = [ 1 0 −r_b.y ]      J_ja = −[ 1 0 −r_a.y ]      (Ċ = v_b + ω_b × r_b − v_a − ω_a × r_a)
//!        [ 0 1  r_b.x ]              [ 0 1  r_a.x ]
//!        [ 0 0  1     ]              [ 0 0  1     ]      (3rd row: C_θ = θ_b − θ_a − θ_ref, Ċ_θ = ω_b − ω_a)
//! ```
//!
//! (the third row only for a 3-row joint, a rigid weld; its bias is
//! `β C_θ` capped at the angular counterpart of the correction speed,
//! [`angular_correction_cap`] (the point rows' `β C` at the correction
//! speed itself, and a `General` joint's rows likewise by kind of row),
//! its `K = J M⁻¹ Jᵀ` the full 3×3 block with the
//! coupling `K₀₂ = −i_a r_a.y − i_b r_b.y`, `K₁₂ = i_a r_a.x + i_b r_b.x`,
//! `K₂₂ = i_a + i_b`, `i = I⁻¹`; see [`crate::weld`]).
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
//! **Heavy trees.** `Γ_j = K_j / a2` builds joint `j`'s spring on its own
//! bodies' masses, so a load `F` stretches it by `F K_j / ω²`: a light link
//! under a heavy bob gives way by `F / (m_link ω²)`, whatever the exact
//! solve does (3.0 cm at 10,000:1 and 500 Hz at the bottom of the swing).
//! In a tree held by a fixed end whose moving bodies' masses span more
//! than [`HEAVY_TREE_RATIO`], every `K_j` in `Γ_j` (and in the held term `Γ_j
//! λ_j`) is instead taken with every moving body as heavy as the tree's
//! heaviest, or [`heavy_spring_factor`] times its lightest if less
//! (300 at the default substep, less for a longer one;
//! [`heavy_spring_inv_mass`], [`spring_inv_mass`]: `1/m → 1/m̃`,
//! `1/I → (m / m̃) / I`). The springs are then stiff on the scale of the
//! load they carry, as the contact groups build theirs on the heaviest
//! body's mass (`janus2d_constraints::contact_group`); the Jacobians,
//! the bodies' pivots and every impulse bound keep the true masses, so
//! momentum is untouched. With no cap the 20-link chain with a heavy end
//! diverged from 2,000:1. Free trees (ragdolls, a lander's legs on its
//! hull) keep their own springs, as they keep their whole feedback in
//! their velocities (see [`VELOCITY_CORRECTION_SPEED`]): built on the
//! heavy mass, the scripted lander of the Python environments no longer
//! reached its portal within its episode.
//!
//! ```text
//!  ratio               10     100    1,000  10,000  100,000
//!  bob, own masses     0.14   0.40   3.0    29.7    3.7e4    mm, peak joint gap
//!  bob, heavy springs  0.14   0.12   0.13   0.27    2.0
//!  chain, own masses   8.3    4.3    6.8    9.2e6   9.8e6
//!  chain, heavy        8.3    0.78   0.22   0.22    2.0
//! ```
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
//!  substitute, root first:      x_k = D_k⁻¹ b_k − L_kᵀ x_p        x_c = D_c⁻¹ b_c − L_cᵀ x_k
//!                               (L_k = J_kpᵀ D_k⁻¹,  L_c = J_kc D_c⁻¹)
//! ```
//!
//! Body pivots (3×3) stay positive definite and joint pivots (`n_k`×`n_k`)
//! negative definite, so both are inverted by cofactors without pivoting.
//!
//! **Joints of 2 and 3 rows.** The branch is per joint, on its row count.
//! A 2-row joint takes the specialised path below (`Mat2` pivots, `J`
//! written out term by term), unchanged from when the tree took only point
//! joints, so a tree of revolute joints gives the same bits as before. A
//! 3-row joint takes general 3×3 blocks (`eliminate_three`,
//! `substitute_three`): `D_k = −Γ_k − J_kc D_c⁻¹ J_kcᵀ`, `T = D_k⁻¹`,
//! `D_p −= J_kpᵀ T J_kp`, `b_p −= J_kpᵀ T b_k`; back substitution
//! `x_k = T b_k − T J_kp x_p`, `x_c = D_c⁻¹ b_c − D_c⁻¹ J_kcᵀ x_k`. Both
//! paths meet in the body pivots (3×3 whatever the joint), so a tree may
//! mix revolute joints and welds. Its angle impulse acts as a torque
//! through the solve's inertia `Ĩ`, is re-weighted at the bias pass like
//! the point impulse's torque, and is written back into the joint (warm
//! start, `constraint_torque`). The geometric stiffness stays on the point
//! rows (the angle row's Jacobian does not turn with the body).
//! `J_ji = ±[I | perp(r)]` has a third of its entries zero and the others
//! ±1 but two, so its products with a pivot are written out term by term:
//! the same sums in the same order as general 3×3 blocks (a joint's padded
//! with `−1` on its unused diagonal), with only the products by an exact 0
//! or ±1 left out, so the result is bit for bit that of the general blocks
//! in about half the operations. A leaf body's `b` stays zero and its
//! solution is not needed, so both are skipped. The
//! elimination runs in f64
//! whatever [`Real`] is: the pivots of a 670:1 chain cost about four digits,
//! which f32 does not have to spare (measured: 3e-3 relative residual in
//! f32 arithmetic at a mass spread of 1e4, 1e-11 in f64), and scalar f64 costs
//! the same as f32 here. A body that cannot
//! translate (or rotate) gets the placeholder mass 1 on that axis and a zero
//! Jacobian column, so its `Δv` there is exactly zero.
//!
//! **Which trees.** A tree held by no fixed end whose masses lie within
//! [`TreePolicy::free_tree_mass_ratio`] and whose longest path is at most
//! the step's Gauss–Seidel sweeps (`2 × substeps` joints) is left to the
//! iterative rows (a ragdoll: Gauss–Seidel holds it as well, for less;
//! figures in docs/architecture.md); it is grown and then dropped
//! (`JointForest::drop_if_iterative`).
//!
//! Only joint components without a loop, and without a joint the tree
//! cannot take (a soft weld, a motor joint: `Joint::tree_rows` is `None`)
//! between two of their moving bodies, are solved directly; a joint the
//! tree cannot take to a fixed end (a mouse joint to the ground) closes no
//! loop, and its rows stay iterative on the tree's body as a contact's
//! do; a joint with no rows at all (a filter joint) is no edge (found by
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

use glam::{DMat3 as Matrix3, DVec2, DVec3};
use janus2d_core::body::BodySet;
use janus2d_core::body::{BodyState, InvMass};
use janus2d_core::constraint::{Constraint, StepContext};
use janus2d_core::math::{Real, Vec2, cross, cross_sv, from_f64, to_f64};
use janus2d_core::parallel::Team;
use janus2d_core::union_find::{find, union};

use crate::joint::Joint;
use crate::joint_base::is_moving;
use crate::kind_rows::{GeneralRows, TreeRows};
use crate::parts::{
    PairMass, PointPart, angular_correction_cap, bounded_sum, cap, clamp_length, row_bound_of_k,
};
use janus2d_core::math::wrap_angle;
use smallvec::SmallVec;

const NONE: u32 = u32::MAX;

/// The point part of a joint without one (never in a tree: the build
/// leaves its component iterative).
const NO_POINT: PointPart = PointPart {
    frame_a: Vec2::ZERO,
    frame_b: Vec2::ZERO,
    delta_center: Vec2::ZERO,
    impulse: Vec2::ZERO,
};

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

/// A joint's pivot: a general 2×2 matrix, `m[row][col]`. It is symmetric
/// up to rounding; both halves are kept so that the elimination repeats,
/// bit for bit, the arithmetic of the padded 3×3 blocks (`[D 0; 0 −1]`)
/// it replaces, with every product by an exact zero or one left out.
#[derive(Clone, Copy, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Mat2 {
    m00: f64,
    m01: f64,
    m10: f64,
    m11: f64,
}

impl Mat2 {
    const ZERO: Mat2 = Mat2 {
        m00: 0.0,
        m01: 0.0,
        m10: 0.0,
        m11: 0.0,
    };

    #[inline(always)]
    fn mul(&self, v: DVec2) -> DVec2 {
        DVec2::new(
            self.m00 * v.x + self.m01 * v.y,
            self.m10 * v.x + self.m11 * v.y,
        )
    }

    /// `D⁻¹` of a definite pivot (the padded block's cofactors over its
    /// determinant `x · (y × z) = −a d + c b`); zero when it is singular or
    /// not finite (the joint then takes no impulse this solve).
    #[inline(always)]
    fn inverse(&self) -> Mat2 {
        let (a, b, c, d) = (self.m00, self.m01, self.m10, self.m11);
        let det = a * -d + c * b;
        let scale = (a * d).abs();
        if !det.is_finite() || det.abs() <= PIVOT_TOLERANCE * scale || det == 0.0 {
            return Mat2::ZERO;
        }
        let q = 1.0 / det;
        Mat2 {
            m00: -d * q,
            m01: b * q,
            m10: c * q,
            m11: -a * q,
        }
    }
}

/// A joint's 2×3 block `J_ji` on one body, with its sign `side` (+1: the
/// joint's body b) and the body's axis masks `l`, `a` (1, or 0 on an axis
/// it cannot move along): `J = [s_l 0 p_x; 0 s_l p_y]`, `s_l = side l`,
/// `(p_x, p_y) = side a (−r.y, r.x)`.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Jacobian {
    lin: f64,
    px: f64,
    py: f64,
    /// `side a`: the angle row's entry (read by 3-row joints only).
    ang: f64,
}

impl Jacobian {
    const ZERO: Jacobian = Jacobian {
        lin: 0.0,
        px: 0.0,
        py: 0.0,
        ang: 0.0,
    };

    #[inline(always)]
    fn new(side: f64, r: Vec2, body: &BodyScratch) -> Jacobian {
        let s_a = side * body.ang;
        Jacobian {
            lin: side * body.lin,
            px: -s_a * to_f64(r.y),
            py: s_a * to_f64(r.x),
            ang: s_a,
        }
    }

    /// The 3×3 block of a 3-row joint (point rows and angle row):
    /// `[s_l 0 p_x; 0 s_l p_y; 0 0 s_a]`, `s_a = side a`.
    #[inline(always)]
    fn full(&self) -> Matrix3 {
        Matrix3::from_cols(
            DVec3::new(self.lin, 0.0, 0.0),
            DVec3::new(0.0, self.lin, 0.0),
            DVec3::new(self.px, self.py, self.ang),
        )
    }

    /// Row `i` (0 or 1) of `L = J S` for a body's `S = D⁻¹`, at column `j`.
    #[inline(always)]
    fn js(&self, s: &Matrix3, i: usize, j: usize) -> f64 {
        let col = s.col(j);
        if i == 0 {
            self.lin * col.x + self.px * col.z
        } else {
            self.lin * col.y + self.py * col.z
        }
    }

    /// A child body folded into its parent joint: `D_k −= L Jᵀ` and
    /// `b_k −= L b_c` with `L = J D_c⁻¹` (`b_c` zero for a leaf).
    #[inline(always)]
    fn fold_body(&self, s: &Matrix3, b_c: Option<DVec3>, d: &mut Mat2, b: &mut DVec2) {
        let l0 = DVec3::new(self.js(s, 0, 0), self.js(s, 0, 1), self.js(s, 0, 2));
        let l1 = DVec3::new(self.js(s, 1, 0), self.js(s, 1, 1), self.js(s, 1, 2));
        d.m00 -= l0.x * self.lin + l0.z * self.px;
        d.m01 -= l0.y * self.lin + l0.z * self.py;
        d.m10 -= l1.x * self.lin + l1.z * self.px;
        d.m11 -= l1.y * self.lin + l1.z * self.py;
        if let Some(v) = b_c {
            b.x -= l0.x * v.x + l0.y * v.y + l0.z * v.z;
            b.y -= l1.x * v.x + l1.y * v.y + l1.z * v.z;
        }
    }

    /// The columns `j` = 0, 1 of `L = Jᵀ T` for a joint's `T = D⁻¹`, each as
    /// its three rows.
    #[inline(always)]
    fn jt_t(&self, t: &Mat2) -> (DVec3, DVec3) {
        let col = |t0: f64, t1: f64| {
            DVec3::new(self.lin * t0, self.lin * t1, self.px * t0 + self.py * t1)
        };
        (col(t.m00, t.m10), col(t.m01, t.m11))
    }

    /// A joint folded into its parent body: `D_p −= L J` and `b_p −= L b_k`
    /// with `L = Jᵀ D_k⁻¹`.
    #[inline(always)]
    fn fold_joint(&self, t: &Mat2, b_k: DVec2, d: &mut Matrix3, b: &mut DVec3) {
        let (c0, c1) = self.jt_t(t);
        d.x_axis -= c0 * self.lin;
        d.y_axis -= c1 * self.lin;
        d.z_axis -= c0 * self.px + c1 * self.py;
        *b -= c0 * b_k.x + c1 * b_k.y;
    }

    /// A joint's solution from its parent's: `x_k = D_k⁻¹ b_k − Lᵀ x_p`.
    #[inline(always)]
    fn joint_solution(&self, t: &Mat2, b_k: DVec2, x_p: DVec3) -> DVec2 {
        let (c0, c1) = self.jt_t(t);
        t.mul(b_k) - DVec2::new(c0.dot(x_p), c1.dot(x_p))
    }

    /// A child body's solution from its joint's: `x_c = D_c⁻¹ b_c − Lᵀ x_k`.
    #[inline(always)]
    fn body_solution(&self, s: &Matrix3, b_c: DVec3, x_k: DVec2) -> DVec3 {
        let lt = |j: usize| self.js(s, 0, j) * x_k.x + self.js(s, 1, j) * x_k.y;
        *s * b_c - DVec3::new(lt(0), lt(1), lt(2))
    }
}

/// A moving body's pivot before elimination: `diag(m, m, Ĩ)` with
/// placeholder 1 on an axis it cannot move along.
#[inline(always)]
fn body_mass(st: &InvMass, added: f64) -> Matrix3 {
    let m = if st.inv_mass > 0.0 {
        1.0 / to_f64(st.inv_mass)
    } else {
        1.0
    };
    let (i, ang) = if st.inv_inertia > 0.0 {
        (1.0 / to_f64(st.inv_inertia), 1.0)
    } else {
        (1.0, 0.0)
    };
    Matrix3::from_diagonal(DVec3::new(m, m, i + ang * added))
}

/// `D⁻¹` of a definite body pivot; zero when it is singular or not finite
/// (the body then takes no part this solve).
#[inline(always)]
fn pivot_inverse(d: &Matrix3) -> Matrix3 {
    let det = d.determinant();
    let scale = (d.x_axis.x * d.y_axis.y * d.z_axis.z).abs();
    if !det.is_finite() || det.abs() <= PIVOT_TOLERANCE * scale || det == 0.0 {
        return Matrix3::ZERO;
    }
    d.inverse()
}

/// A tree body's scratch in the tree solve.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct BodyScratch {
    /// A copy of its state while the tree is solved.
    state: BodyState,
    /// Its inverse mass and inertia (as its joints loaded them).
    mass: InvMass,
    /// The pivot `D_k` while eliminating, then `D_k⁻¹`.
    d: Matrix3,
    /// The right-hand side, then the solution.
    b: DVec3,
    /// Axis masks: 1 where the body translates (rotates), else 0.
    lin: f64,
    ang: f64,
    /// No joint of the tree has this body as its parent: its right-hand
    /// side stays zero and its solution is not needed.
    leaf: bool,
    /// First the geometric stiffness term `K_g = h Σ max(0, ±λ · r)`, then
    /// the inertia added for it, `max(0, K_g / GEOMETRIC_RATIO − I)` (see
    /// the module docs), kg·m².
    geometric: f64,
    /// The geometric stiffness term from its parent joint (added last).
    geometric_up: f64,
    /// `Ĩ⁻¹ − I⁻¹` (≤ 0): how much the added inertia lowers the inverse
    /// inertia the solve's impulses act through.
    inertia_change: Real,
}

impl BodyScratch {
    const ZERO: BodyScratch = BodyScratch {
        state: BodyState::IDENTITY,
        mass: InvMass::ZERO,
        d: Matrix3::ZERO,
        b: DVec3::ZERO,
        lin: 0.0,
        ang: 0.0,
        leaf: true,
        geometric: 0.0,
        geometric_up: 0.0,
        inertia_change: 0.0,
    };

    /// Sets its inverse masses and the axis masks they give.
    #[inline(always)]
    fn set_mass(&mut self, mass: InvMass) {
        self.mass = mass;
        self.lin = if mass.inv_mass > 0.0 { 1.0 } else { 0.0 };
        self.ang = if mass.inv_inertia > 0.0 { 1.0 } else { 0.0 };
    }

    /// Turns the body by an impulse `p` at arm `r` on `side` (+1: the
    /// joint's body b) through the inertia added for the solve: the
    /// re-weighting of a torque applied through `I` to `Ĩ`.
    #[inline(always)]
    fn reweight(&mut self, side: f64, r: Vec2, p: Vec2) {
        self.state.w += (from_f64(side) * self.inertia_change) * cross(r, p);
    }

    /// Re-weights an angular impulse `l` on `side` applied through `I` to
    /// `Ĩ` (a 3-row joint's angle row).
    #[inline(always)]
    fn reweight_angle(&mut self, side: f64, l: Real) {
        self.state.w += (from_f64(side) * self.inertia_change) * l;
    }

    /// Applies the angular impulse `l` on `side` (+1: body b takes `+l`;
    /// −1: body a, `−l`) through `Ĩ` (a 3-row joint's angle row).
    #[inline(always)]
    fn apply_angle(&mut self, side: f64, l: Real) {
        let inv_i = self.mass.inv_inertia + self.inertia_change;
        self.state.w += (from_f64(side) * inv_i) * l;
    }

    /// Applies the impulse `p` at arm `r` on `side` (+1: the joint's body
    /// b, which takes `+p`; −1: body a, `−p`), turning through `Ĩ`.
    /// Applies `Jᵀ Δλ` of a block of rows (rows × (x, y, ω)) through the
    /// solve's masses.
    #[inline(always)]
    fn apply_rows(&mut self, j: &Matrix3, delta: DVec3) {
        let f = j.transpose() * delta;
        let inv_i = self.mass.inv_inertia + self.inertia_change;
        self.state.v += self.mass.inv_mass * Vec2::new(from_f64(f.x), from_f64(f.y));
        self.state.w += inv_i * from_f64(f.z);
    }

    #[inline(always)]
    fn apply(&mut self, side: f64, r: Vec2, p: Vec2) {
        let st = &mut self.state;
        let side = from_f64(side);
        let inv_i = self.mass.inv_inertia + self.inertia_change;
        st.v += (side * self.mass.inv_mass) * p;
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
    /// `J` on its parent body and on its child body (if any).
    jac_parent: Jacobian,
    jac_child: Jacobian,
    /// The separation `C = (x_b + r_b) − (x_a + r_a)`, m.
    c: Vec2,
    /// A copy of its accumulated point impulse, N·s.
    impulse: Vec2,
    /// The state index of its fixed end (read when it has no child body).
    fixed: u32,
    /// The joint's inverse masses (its bodies a and b).
    masses: PairMass,
    /// The pivot `D_k` while eliminating, then `D_k⁻¹` (2-row joints).
    d: Mat2,
    /// The right-hand side, then the solution `μ` (2-row joints).
    b: DVec2,
    /// True for a 3-row joint (point and angle rows): the fields below
    /// are its angle row and its 3×3 pivot, and `d`, `b` are unused.
    three: bool,
    /// The angle error `C_θ = θ_b − θ_a − θ_ref`, rad.
    c_angle: Real,
    /// A copy of its accumulated angle impulse, N·m·s.
    angle_impulse: Real,
    /// A `General` joint: solved by the general 3×3 path (its
    /// [`WideScratch`]).
    general: bool,
    /// The bias pass left part of its feedback to the correction pass
    /// (see [`VELOCITY_CORRECTION_SPEED`]).
    split: bool,
    /// That part: the point rows' (m/s) and the angle row's (rad/s).
    rest: Vec2,
    rest_angle: Real,
}

/// The part of a tree joint's scratch only 3-row and `General` joints
/// use, kept apart so the 2-row joints' scratch stays compact (a
/// point-only tree never touches it).
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct WideScratch {
    /// The pivot `D_k` while eliminating, then `D_k⁻¹` (3-row joints).
    d3: Matrix3,
    /// The right-hand side, then the solution `μ` (3-row joints).
    b3: DVec3,
    /// Its rows on the parent body (rows past its count are zero), masked
    /// like the point Jacobians.
    g_parent: Matrix3,
    /// Its rows on the child body (masked), or on the fixed end (unmasked,
    /// for `Ċ` only).
    g_child: Matrix3,
    /// Its `K = J M⁻¹ Jᵀ` from the joint's own masses.
    g_k: Matrix3,
    /// Its `K` on the masses its springs are built on
    /// ([`compliance_masses`]), set only in a heavy tree (read it through
    /// [`WideScratch::spring_k`]).
    g_k_spring: Matrix3,
    /// Its errors.
    g_c: DVec3,
    /// A copy of its accumulated impulses.
    g_impulse: [Real; 3],
    /// Which of its rows have their correction speed capped.
    g_linear: [bool; 3],
    /// The part of its rows' feedback left to the correction pass.
    g_rest: DVec3,
    /// Its number of rows.
    g_count: usize,
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
        masses: PairMass::ZERO,
        d: Mat2::ZERO,
        b: DVec2::ZERO,
        three: false,
        c_angle: 0.0,
        angle_impulse: 0.0,
        general: false,
        split: false,
        rest: Vec2::ZERO,
        rest_angle: 0.0,
    };
}

impl WideScratch {
    const ZERO: WideScratch = WideScratch {
        d3: Matrix3::ZERO,
        b3: DVec3::ZERO,
        g_parent: Matrix3::ZERO,
        g_child: Matrix3::ZERO,
        g_k: Matrix3::ZERO,
        g_k_spring: Matrix3::ZERO,
        g_c: DVec3::ZERO,
        g_impulse: [0.0; 3],
        g_linear: [false; 3],
        g_rest: DVec3::ZERO,
        g_count: 0,
    };

    /// The `K` its springs are built on: `g_k_spring` in a heavy tree,
    /// its own `g_k` otherwise.
    #[inline(always)]
    fn spring_k(&self, params: &TreeParams) -> Matrix3 {
        if params.heavy_inv_mass > 0.0 {
            self.g_k_spring
        } else {
            self.g_k
        }
    }
}

impl Default for JointScratch {
    fn default() -> Self {
        Self::ZERO
    }
}

impl Default for WideScratch {
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
    /// Per tree joint: the 3-row and general rows' part of its scratch.
    wide_scratch: Vec<WideScratch>,
    /// Per tree: the last bias pass left it a position correction.
    correct: Vec<bool>,
    /// Per joint: its moving ends this step (see `moving_pair`).
    pairs: Vec<[u32; 3]>,
    /// The pairs and policy the forest was last built from.
    built_pairs: Vec<[u32; 3]>,
    built_policy: Option<TreePolicy>,
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

/// A joint's two state indices, 0 for an end the tree does not move
/// (static, kinematic, sleeping), `[0, 0]` for a disabled joint; and its
/// `in_tree` flag, so that a joint created since the last build (flag
/// unset) forces a rebuild even where the ends repeat.
#[inline]
pub(crate) fn moving_pair(j: &Joint, states: &[BodyState]) -> [u32; 3] {
    let base = j.base();
    let flags = u32::from(base.in_tree)
        | if j.tree_rows().is_some() {
            0
        } else {
            ITERATIVE
        };
    if !base.enabled || base.rows == 0 {
        // Nothing to solve (a filter joint): not an edge at all.
        return [0, 0, flags];
    }
    let end = |s: u32| if is_moving(states, s) { s } else { 0 };
    let (a, b) = (end(base.state_a), end(base.state_b));
    let flags = if a != 0 && b != 0 {
        flags | mass_bucket(base.masses.a.inv_mass, base.masses.b.inv_mass) << MASS_SHIFT
    } else {
        flags
    };
    [a, b, flags]
}

/// Pair flags from this bit up: the joint's own mass ratio in quarter
/// octaves (see `mass_bucket`), so that a body's mass changed by more
/// than about a fifth rebuilds the forest and its free-tree choice.
const MASS_SHIFT: u32 = 2;

/// The ratio of two moving bodies' masses (from their inverse masses) in
/// quarter octaves, 0 … 63 (63 for a body of infinite mass): the f32
/// exponent of the ratio and the top two bits of its mantissa, above
/// those of 1. A bit shift, not a logarithm: every joint's pair is formed
/// at every step.
#[inline]
fn mass_bucket(inv_a: Real, inv_b: Real) -> u32 {
    let (lo, hi) = if inv_a < inv_b {
        (inv_a, inv_b)
    } else {
        (inv_b, inv_a)
    };
    let ratio = to_f64(hi / lo) as f32;
    if lo <= 0.0 || !ratio.is_finite() {
        return 63;
    }
    ((ratio.to_bits() - 1.0f32.to_bits()) >> 21).min(63)
}

/// True when one of a tree's joints (`tree`, breadth-first) ends at a
/// fixed body (static, kinematic or sleeping): it has no child.
#[inline]
fn is_anchored(tree: &[TreeJoint]) -> bool {
    tree.iter().any(|tj| tj.child == NONE)
}

/// The longest path of a tree, in joints, from its joints in
/// breadth-first order (`tree`, local body indices) over `bodies` bodies:
/// each body's height above its deepest leaf, children before parents.
fn tree_diameter(tree: &[TreeJoint], bodies: usize) -> usize {
    // Per body: the two largest heights among its child subtrees (+1).
    let mut heights: SmallVec<[(usize, usize); 32]> = SmallVec::new();
    heights.resize(bodies, (0, 0));
    let mut diameter = 0;
    for tj in tree.iter().rev() {
        let below = if tj.child == NONE {
            1
        } else {
            heights[tj.child as usize].0 + 1
        };
        let h = &mut heights[tj.parent as usize];
        if below > h.0 {
            *h = (below, h.0);
        } else if below > h.1 {
            h.1 = below;
        }
        diameter = diameter.max(h.0 + h.1);
    }
    diameter
}

/// Which joint trees the forest solves directly: the world's
/// [`SolverSettings::direct_joints`](janus2d_core::solver::SolverSettings::direct_joints)
/// and
/// [`SolverSettings::direct_free_tree_mass_ratio`](janus2d_core::solver::SolverSettings::direct_free_tree_mass_ratio).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct TreePolicy {
    /// Any tree at all (false: every joint iterative).
    pub enabled: bool,
    /// A tree held by no fixed end is solved directly only if the spread
    /// of its moving bodies' masses (heaviest ÷ lightest) reaches this
    /// (dimensionless; `≤ 1`: every tree), or its longest path is more
    /// joints than `2 × substeps`.
    pub free_tree_mass_ratio: Real,
    /// Substeps per step (each a solve and a relax sweep).
    pub substeps: u32,
}

impl TreePolicy {
    /// Every tree, whatever its masses (`enabled` false: none).
    #[must_use]
    pub const fn every_tree(enabled: bool) -> TreePolicy {
        TreePolicy {
            enabled,
            free_tree_mass_ratio: 0.0,
            substeps: 1,
        }
    }

    /// The step's policy.
    #[must_use]
    pub fn of(ctx: &StepContext) -> TreePolicy {
        TreePolicy {
            enabled: ctx.direct_joints,
            free_tree_mass_ratio: ctx.direct_free_tree_mass_ratio,
            substeps: ctx.substeps,
        }
    }
}

/// Pair flag: the joint was in the tree when the forest was last built.
const IN_TREE: u32 = 1;

/// Pair flag: the tree solve cannot take the joint's rows (its kind has
/// no point part, or it is soft), so a component holding it stays wholly
/// iterative.
const ITERATIVE: u32 = 2;

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
    /// (`in_tree`): every tree, whatever its masses
    /// ([`TreePolicy::every_tree`]). With `enabled` false every joint stays
    /// iterative.
    pub fn build(&mut self, joints: &mut [Joint], states: &[BodyState], enabled: bool) {
        for (pair, j) in self.pairs_for(joints.len()).iter_mut().zip(joints.iter()) {
            *pair = moving_pair(j, states);
        }
        self.update(joints, states.len(), TreePolicy::every_tree(enabled));
    }

    /// The buffer of this step's pairs, one per joint, for a caller that
    /// fills it with [`moving_pair`] in its own pass over the joints (the
    /// batch's prepare does, while each joint is in cache) before
    /// [`JointForest::update`].
    pub(crate) fn pairs_for(&mut self, joint_count: usize) -> &mut [[u32; 3]] {
        self.pairs.resize(joint_count, [0; 3]);
        &mut self.pairs
    }

    /// Prepares every enabled joint and finds the forest in the same pass
    /// over the joints (the batch's `prepare`).
    pub fn prepare(&mut self, joints: &mut [Joint], ctx: &StepContext, bodies: &BodySet) {
        self.pairs.clear();
        for j in joints.iter_mut() {
            if j.is_enabled() {
                j.prepare(ctx, bodies);
            }
            self.pairs.push(moving_pair(j, &bodies.states));
        }
        self.update(joints, bodies.states.len(), TreePolicy::of(ctx));
    }

    /// Rebuilds the forest when the joints' moving ends changed since the
    /// last build (joints created, destroyed, enabled or disabled, bodies
    /// woken, put to sleep or re-indexed); otherwise keeps it.
    /// Whether it rebuilt: a rebuild may move joints into or out of trees
    /// (`in_tree`), which decides whether they keep Gauss–Seidel rows.
    pub(crate) fn update(&mut self, joints: &mut [Joint], n: usize, policy: TreePolicy) -> bool {
        if Some(policy) == self.built_policy && self.pairs == self.built_pairs {
            return false;
        }
        self.rebuild(joints, n, policy);
        self.built_policy = Some(policy);
        self.built_pairs.clone_from(&self.pairs);
        for (pair, j) in self.built_pairs.iter_mut().zip(joints.iter()) {
            pair[2] = (pair[2] & !IN_TREE) | u32::from(j.in_tree());
        }
        true
    }

    fn rebuild(&mut self, joints: &mut [Joint], n: usize, policy: TreePolicy) {
        let enabled = policy.enabled;
        self.trees.clear();
        self.bodies.clear();
        self.joints.clear();
        self.parent_joint.clear();
        self.tree_joints.clear();
        for j in joints.iter_mut() {
            j.base_mut().in_tree = false;
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
        for &[a, b, flags] in &self.pairs {
            if a == 0 || b == 0 {
                // A joint to a fixed end closes no loop; one the tree
                // cannot take (a mouse, a motor joint, a spring to the
                // ground) is no tree edge: its rows stay iterative on
                // the tree's body, as a contact's do.
                continue;
            }
            if flags & ITERATIVE != 0 {
                // Between two moving bodies a joint the tree cannot take
                // would couple exact rows to soft ones around a loop: its
                // component stays iterative, like one with a loop.
                for s in [a, b] {
                    let root = find(&mut self.union, s);
                    self.cyclic[root as usize] = true;
                }
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
        for (i, &[a, b, flags]) in self.pairs.iter().enumerate() {
            if (a == 0 && b == 0) || flags & ITERATIVE != 0 {
                continue;
            }
            let root = find(&mut self.union, if a != 0 { a } else { b });
            if self.cyclic[root as usize] {
                continue;
            }
            joints[i].base_mut().in_tree = true;
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
        let mut dropped = false;
        for t in 0..self.tree_joints.len() {
            let [a, b, _] = self.pairs[self.tree_joints[t] as usize];
            for root in [a, b] {
                if root != 0 && !self.visited[root as usize] {
                    self.grow(root);
                    dropped |= self.drop_if_iterative(joints, policy);
                }
            }
        }
        if dropped {
            self.tree_joints.retain(|&i| joints[i as usize].in_tree());
        }
        self.body_scratch
            .resize(self.bodies.len(), BodyScratch::ZERO);
        self.joint_scratch
            .resize(self.joints.len(), JointScratch::ZERO);
        self.wide_scratch
            .resize(self.joints.len(), WideScratch::ZERO);
    }

    /// Takes the tree just grown out of the forest again when
    /// Gauss–Seidel holds it as well (see
    /// [`TreePolicy::free_tree_mass_ratio`]): held by no fixed end, its
    /// masses within the ratio, and its longest path no more joints than
    /// the sweeps a step makes (solve and relax in each substep), so an
    /// impulse crosses it within the step. Its joints go back to the
    /// iterative rows. Returns whether it was dropped.
    fn drop_if_iterative(&mut self, joints: &mut [Joint], policy: TreePolicy) -> bool {
        let Some(&start) = self.trees.last() else {
            return false;
        };
        let tree = &self.joints[start.joints as usize..];
        if is_anchored(tree) {
            return false;
        }
        // The moving bodies' inverse masses, from their joints (a free
        // tree's joints all have two moving ends).
        let (mut inv_heaviest, mut inv_lightest): (Real, Real) = (Real::MAX, 0.0);
        for tj in tree {
            let m = &joints[tj.index as usize].base().masses;
            inv_heaviest = inv_heaviest.min(m.a.inv_mass).min(m.b.inv_mass);
            inv_lightest = inv_lightest.max(m.a.inv_mass).max(m.b.inv_mass);
        }
        // m_heaviest ÷ m_lightest < ratio, as products (a zero inverse
        // mass is an infinite spread).
        let even = inv_heaviest > 0.0 && inv_lightest < policy.free_tree_mass_ratio * inv_heaviest;
        if !even
            || tree_diameter(tree, self.bodies.len() - start.bodies as usize)
                > 2 * policy.substeps as usize
        {
            return false;
        }
        for tj in tree {
            joints[tj.index as usize].base_mut().in_tree = false;
        }
        self.trees.pop();
        self.joints.truncate(start.joints as usize);
        self.bodies.truncate(start.bodies as usize);
        self.parent_joint.truncate(start.bodies as usize);
        true
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
        joints: &mut [Joint],
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
        joints: &mut [Joint],
        states: &mut [BodyState],
        use_bias: bool,
        team: &Team,
    ) {
        if self.trees.is_empty() {
            return;
        }
        let softness = ctx.direct_joint_softness;
        let mut params = TreeParams {
            softness,
            compliance: if softness.mass_scale > 0.0 {
                to_f64(softness.impulse_scale) / to_f64(softness.mass_scale)
            } else {
                0.0
            },
            h: to_f64(ctx.h),
            max_correction_speed: ctx.direct_joint_max_correction_speed,
            use_bias,
            correct: false,
            anchored: false,
            heavy_inv_mass: 0.0,
        };
        self.solve_trees(joints, states, &params, team, false);
        for (&s, sc) in self.bodies.iter().zip(&self.body_scratch) {
            let st = &mut states[s as usize];
            st.v = sc.state.v;
            st.w = sc.state.w;
        }
        let rows = self.joint_scratch.iter().zip(&self.wide_scratch);
        for (tj, (row, wide)) in self.joints.iter().zip(rows) {
            let impulses = if row.general {
                wide.g_impulse
            } else {
                [row.impulse.x, row.impulse.y, row.angle_impulse]
            };
            joints[tj.index as usize].set_tree_impulses(impulses);
        }
        if !use_bias {
            return;
        }
        // The trees whose feedback the bias pass split: their position
        // correction, on pseudo-velocities (see VELOCITY_CORRECTION_SPEED).
        self.correct.clear();
        let mut any = false;
        for (t, start) in self.trees.iter().enumerate() {
            let end = self
                .trees
                .get(t + 1)
                .map_or(self.joints.len(), |n| n.joints as usize);
            let split = self.joint_scratch[start.joints as usize..end]
                .iter()
                .any(|row| row.split);
            any |= split;
            self.correct.push(split);
        }
        if !any {
            return;
        }
        params.use_bias = false;
        params.correct = true;
        params.compliance *= CORRECTION_COMPLIANCE;
        self.solve_trees(joints, states, &params, team, true);
        let h = ctx.h;
        for (t, start) in self.trees.iter().enumerate() {
            if !self.correct[t] {
                continue;
            }
            let end = self
                .trees
                .get(t + 1)
                .map_or(self.bodies.len(), |n| n.bodies as usize);
            let range = start.bodies as usize..end;
            for (&s, sc) in self.bodies[range.clone()]
                .iter()
                .zip(&self.body_scratch[range])
            {
                let st = &mut states[s as usize];
                st.dp += h * sc.state.v;
                st.dq = st.dq.integrate(h * sc.state.w);
            }
        }
    }

    /// One pass of [`solve_tree`] over every tree (with `only_marked`,
    /// over the trees marked in `correct`), on the team.
    fn solve_trees(
        &mut self,
        joints: &[Joint],
        states: &[BodyState],
        params: &TreeParams,
        team: &Team,
        only_marked: bool,
    ) {
        let (bodies, tree_joints) = (&self.bodies[..], &self.joints[..]);
        let mut rest_bodies = &mut self.body_scratch[..];
        let mut rest_joints = &mut self.joint_scratch[..];
        let mut rest_wide = &mut self.wide_scratch[..];
        let starts = &self.trees;
        let marked = &self.correct;
        let split = starts.iter().enumerate().filter_map(move |(t, &start)| {
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
            let (wide_scratch, tail) =
                std::mem::take(&mut rest_wide).split_at_mut(joint_range.len());
            rest_wide = tail;
            (!only_marked || marked[t]).then_some(Tree {
                states: &bodies[body_range],
                joints: &tree_joints[joint_range],
                bodies: body_scratch,
                rows: joint_scratch,
                wide: wide_scratch,
            })
        });
        if team.threads() == 1 {
            // Tree by tree, without collecting the split.
            for mut tree in split {
                solve_tree(&mut tree, joints, states, params);
            }
        } else {
            let mut trees: Vec<_> = split.collect();
            let per_block = trees.len().div_ceil(4 * team.threads()).max(1);
            team.for_each_chunk_mut(&mut trees, per_block, |_, block| {
                for tree in block.iter_mut() {
                    solve_tree(tree, joints, states, params);
                }
            });
        }
    }
}

impl TreeParams {
    /// The cap of a linear row's feedback, m/s: an anchored tree's
    /// correction reaches CORRECTION_SPEED_FACTOR times the setting (only
    /// [`VELOCITY_CORRECTION_SPEED`] of it in the velocities).
    #[inline(always)]
    fn linear_cap(&self) -> Real {
        if self.anchored {
            self.max_correction_speed * CORRECTION_SPEED_FACTOR
        } else {
            self.max_correction_speed
        }
    }
}

/// The step constants of one tree solve.
#[derive(Clone, Copy)]
struct TreeParams {
    softness: janus2d_core::softness::Softness,
    /// `Γ / K = impulse_scale / mass_scale`.
    compliance: f64,
    /// Substep, s.
    h: f64,
    /// Largest correction speed, m/s.
    max_correction_speed: Real,
    use_bias: bool,
    /// The position correction pass (see [`VELOCITY_CORRECTION_SPEED`]):
    /// only the feedback above that speed, on pseudo-velocities.
    correct: bool,
    /// The tree is held by a fixed end, so its feedback is split between
    /// the velocity solve and the correction pass (set per tree).
    anchored: bool,
    /// The inverse mass its joints' springs are built on, 1/kg, when it is
    /// anchored and its moving bodies' masses span more than
    /// [`HEAVY_TREE_RATIO`] (set per tree, [`heavy_spring_inv_mass`]; 0
    /// otherwise: each joint's own).
    heavy_inv_mass: Real,
}

/// Mass spread within a tree (heaviest ÷ lightest moving body,
/// dimensionless) above which its joints' springs are built on a heavier
/// mass ([`heavy_spring_inv_mass`]).
pub const HEAVY_TREE_RATIO: Real = 10.0;

/// The most a heavy tree's springs are stiffened, as a factor on the
/// lightest body's (dimensionless): its springs are built on the mass of
/// its heaviest body or of 300 times its lightest, whichever is less.
/// Unbounded, the 20-link chain with a heavy end diverged from 2,000:1
/// (springs 2,000× stiffer than the links'; at 1,000× it opened to 9.4
/// cm at 2,000:1); at 300× every ratio from 10:1 to 300,000:1 holds its
/// joints within 2.1 mm (`mass_ratio_sweep`).
pub const HEAVY_SPRING_FACTOR: Real = 300.0;

/// The substep (s) at which [`HEAVY_SPRING_FACTOR`] was measured: steps of
/// 1/60 s in 4 substeps.
pub const HEAVY_SPRING_SUBSTEP: Real = 1.0 / 240.0;

/// The stiffening cap of a heavy tree's springs for a substep of `h`
/// seconds (dimensionless): [`HEAVY_SPRING_FACTOR`] up to
/// [`HEAVY_SPRING_SUBSTEP`], and `HEAVY_SPRING_FACTOR (h₀ / h)²` for a
/// longer substep.
///
/// The directly solved joints' spring has a fixed frequency `ω` (the
/// direct joint hertz, 500 Hz); built on a mass `f` times a light body's,
/// it pulls that body at `ω √f`. Scaling `f` by `(h₀ / h)²` keeps `ω √f h`,
/// the light body's spring phase per substep, where it was measured
/// stable. At 2 substeps (75×) the 20-link chain with a 1,000:1 end holds
/// its joints within 0.7 mm; at 300× it diverged there (5.4 m gaps, from
/// about 6 s), as did 2,000:1 and 5,000:1.
#[must_use]
pub fn heavy_spring_factor(h: Real) -> Real {
    // (A substep within rounding of h₀, as 1/60 s in 4, takes the factor
    // as it is.)
    if h <= HEAVY_SPRING_SUBSTEP * 1.001 {
        HEAVY_SPRING_FACTOR
    } else {
        let r = HEAVY_SPRING_SUBSTEP / h;
        HEAVY_SPRING_FACTOR * r * r
    }
}

/// The masses a joint's spring is built on: its own, or, in an anchored
/// tree whose masses span more than [`HEAVY_TREE_RATIO`], every moving body as heavy
/// as the tree's spring mass (see [`spring_inv_mass`]). The soft row's
/// static stretch under a load `F` is `F K / ω²`; on the light links'
/// own `K` a heavy load stretches them by `F / (m_link ω²)` (1 cm at
/// 10,000:1 and 500 Hz before any swing), on the heavy mass's by
/// `F / (m_spring ω²)`.
#[inline(always)]
fn compliance_masses(m: &PairMass, params: &TreeParams) -> PairMass {
    let heavy = params.heavy_inv_mass;
    if heavy <= 0.0 {
        return *m;
    }
    let scale = |b: InvMass| {
        let (inv_mass, inv_inertia) = spring_inv_mass(b.inv_mass, b.inv_inertia, heavy);
        InvMass {
            inv_mass,
            inv_inertia,
        }
    };
    PairMass {
        a: scale(m.a),
        b: scale(m.b),
    }
}

/// A moving body's inverse mass and inertia (1/kg, 1/(kg·m²)) as a heavy
/// tree's springs see it, given the tree's spring inverse mass `heavy`
/// (from [`heavy_spring_inv_mass`]; 0: the body's own): `1/m → heavy`,
/// `1/I → (heavy · m) / I`, the body's shape kept. A fixed body (0) stays.
#[inline(always)]
#[must_use]
pub fn spring_inv_mass(inv_mass: Real, inv_inertia: Real, heavy: Real) -> (Real, Real) {
    if heavy > 0.0 && inv_mass > 0.0 {
        (heavy, inv_inertia * (heavy / inv_mass))
    } else {
        (inv_mass, inv_inertia)
    }
}

/// The inverse mass (1/kg) a tree's joint springs are built on, from its
/// moving bodies' inverse masses: where the heaviest is more than
/// [`HEAVY_TREE_RATIO`] times the lightest, the heaviest body's mass or
/// `factor` times the lightest's ([`heavy_spring_factor`] of the
/// substep), whichever is less; 0 (each joint's own masses) otherwise.
#[must_use]
pub fn heavy_spring_inv_mass(inv_masses: impl IntoIterator<Item = Real>, factor: Real) -> Real {
    let (mut lightest, mut heaviest) = (0.0 as Real, Real::MAX);
    for inv in inv_masses {
        if inv > 0.0 {
            lightest = lightest.max(inv);
            heaviest = heaviest.min(inv);
        }
    }
    if heaviest < Real::MAX && lightest > HEAVY_TREE_RATIO * heaviest {
        heaviest.max(lightest / factor)
    } else {
        0.0
    }
}

/// [`heavy_spring_inv_mass`] of a tree's moving bodies, read from its
/// joints' loaded masses, for a substep of `h` seconds.
fn heavy_inv_mass(tree: &[TreeJoint], joints: &[Joint], h: f64) -> Real {
    let inv_masses = tree.iter().flat_map(|tj| {
        let m = joints[tj.index as usize].base().masses;
        [m.a.inv_mass, m.b.inv_mass]
    });
    heavy_spring_inv_mass(inv_masses, heavy_spring_factor(h as Real))
}

/// Largest position-feedback speed of one tree joint that goes into the
/// bodies' velocities, m/s (rad/s for angle rows, through
/// [`angular_correction_cap`]), beyond what its softness holds (see
/// `velocity_share`). A larger error's feedback (up to
/// `direct_joint_max_correction_speed`) is split: this much in the
/// velocity solve, the rest in a second, position-only solve of the same
/// tree on pseudo-velocities (Catto's split impulses), which moves the
/// bodies and adds no speed:
///
/// ```text
/// bias pass:        J Δv + Γ Δλ = −(Ċ + b_v + Γ λ)     b_v = β C capped at v_vel + |Γ λ|
/// correction pass:  J Δv_b + ε Γ Δλ_b = −(b − b_v)      b   = β C capped at v_max
///                   dp += h Δv_b,  dq ← dq ⊕ h Δω_b      (Δv_b, Δλ_b then dropped)
/// ```
///
/// With the whole feedback in the velocities, a chain hung 2× stretched
/// (40 circles) reached 48 m/s where the same chain unstretched does not
/// move, and the stretched-chain family (`janus2d_testbed::hard`) passed
/// 4 of 36 at 4 substeps: the relax pass that removes the correction's
/// speed is soft, and its compliance acts on the impulse that stops the
/// whole subtree below a joint, so part of the speed stays; made rigid,
/// its impulses compress the closing chain and it buckles (links spinning
/// at 40 rad/s). The correction solve is nearly rigid
/// (`CORRECTION_COMPLIANCE`: with the joints' own softness a 40-link
/// chain's root joints closed at 2% of the asked speed) and moves the
/// bodies rather than turning them (`CORRECTION_INERTIA`). Its metric
/// does not touch momentum: the pseudo-velocities are not kept. A joint
/// whose feedback stays below its share (every joint of the benchmark
/// scenes' ragdolls at rest) never reaches the second solve, which then
/// costs nothing.
pub const VELOCITY_CORRECTION_SPEED: Real = 0.1;

/// The correction solve's compliance as a fraction of the joints' own
/// (dimensionless): nearly rigid, so a long chain's joints near its root
/// close at the asked speed (with the joints' own, 0.04 of 1.9 m/s at the
/// sixth of 40 links). Kept above zero so that a joint to a fixed end
/// keeps a definite pivot.
const CORRECTION_COMPLIANCE: f64 = 1.0e-4;

/// The correction solve's rotational inertia, as a multiple of `m r²`
/// for a body's longest joint arm `r` (dimensionless): a gap is closed by
/// moving the bodies rather than by turning light links through large
/// angles, whose linearisation zig-zagged a lying 40-link chain (late gap
/// 0.54 m at `m r²`; 10: 25 of the 36 family members, 100: 36).
const CORRECTION_INERTIA: f64 = 100.0;

/// How far above `direct_joint_max_correction_speed` an anchored tree's
/// correction may go (dimensionless): the velocity solve keeps at most
/// [`VELOCITY_CORRECTION_SPEED`] of it, so the cap no longer bounds speed
/// added, only how far the bodies move in a substep (at 2 m/s × 5 a
/// joint closes 4 cm per substep at 240 Hz). The stretched-chain family
/// passed 17 of 36 at the cap itself, 30 at 2.5×, 36 at 5×.
const CORRECTION_SPEED_FACTOR: Real = 5.0;

/// The largest feedback speed a tree joint's row keeps in the velocity
/// solve, m/s, given the speed `held` (m/s) its softness term `Γ λ` asks
/// for: [`VELOCITY_CORRECTION_SPEED`] plus that, so a joint holding a load
/// keeps the feedback that balances its softness (its static stretch,
/// where `β C = Γ λ`) where it was, and only an error beyond it is moved
/// by the correction pass. (With all of it above 0.1 m/s moved, the
/// 670:1 ball and chain opened to 4.2 m and the bridge to 0.54 m.)
#[inline(always)]
fn velocity_share(held: Real, params: &TreeParams) -> Real {
    if params.anchored {
        VELOCITY_CORRECTION_SPEED + held
    } else {
        Real::MAX
    }
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
    /// Per joint: the 3-row and general rows' scratch.
    wide: &'a mut [WideScratch],
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
fn solve_tree(tree: &mut Tree<'_>, joints: &[Joint], states: &[BodyState], params: &TreeParams) {
    // A tree held by a fixed end splits its feedback (see
    // VELOCITY_CORRECTION_SPEED) up to CORRECTION_SPEED_FACTOR times the
    // cap; a free tree keeps all of it, at the cap, in its velocities.
    let anchored = is_anchored(tree.joints);
    let params = &TreeParams {
        anchored,
        // Free trees (ragdolls, vehicles) keep their joints' own springs,
        // as they keep the whole feedback in their velocities.
        heavy_inv_mass: if anchored {
            heavy_inv_mass(tree.joints, joints, params.h)
        } else {
            0.0
        },
        ..*params
    };
    let TreeParams {
        softness,
        compliance,
        h,
        max_correction_speed: _,
        use_bias,
        correct,
        anchored: _,
        heavy_inv_mass: _,
    } = *params;
    let Tree {
        states: indices,
        joints: topology,
        bodies,
        rows,
        wide: extra,
    } = tree;
    let (topology, bodies, rows, extra) = (&**topology, &mut **bodies, &mut **rows, &mut **extra);
    for (sc, &s) in bodies.iter_mut().zip(indices.iter()) {
        sc.state = states[s as usize];
        if correct {
            // The correction solves for pseudo-velocities from zero.
            sc.state.v = Vec2::ZERO;
            sc.state.w = 0.0;
        }
        sc.leaf = true;
        sc.geometric = 0.0;
        sc.geometric_up = 0.0;
    }
    // The bodies' inverse masses as their joints loaded them: the root's
    // from its first joint (the tree's first), every other body's from its
    // parent joint (which comes before the body's own joints).
    if let Some(first) = topology.first() {
        debug_assert_eq!(first.parent, 0, "a tree's first joint hangs from its root");
        let m = joints[first.index as usize].base().masses;
        bodies[0].set_mass(if first.side > 0.0 { m.b } else { m.a });
    }
    // Arms, separations, Jacobians and impulses of the joints, and the
    // geometric stiffness each body takes from its joints.
    for ((tj, row), w) in topology.iter().zip(rows.iter_mut()).zip(extra.iter_mut()) {
        let j = &joints[tj.index as usize];
        let tree_rows = j.tree_rows();
        let base = j.base();
        let side = tj.side;
        row.masses = base.masses;
        row.general = matches!(tree_rows, Some(TreeRows::General { .. }));
        row.split = false;
        if row.general {
            general_rows(tj, row, w, j, bodies, states, params);
            if correct {
                w.g_impulse = [0.0; 3];
            }
            continue;
        }
        let (point, tree_angle) = match tree_rows {
            Some(TreeRows::Point { point, angle }) => (point, angle),
            _ => (&NO_POINT, None),
        };
        let (frame_parent, frame_other, fixed) = if side > 0.0 {
            (point.frame_b, point.frame_a, base.state_a)
        } else {
            (point.frame_a, point.frame_b, base.state_b)
        };
        row.fixed = fixed;
        let parent = &bodies[tj.parent as usize];
        let other = other_end(tj, fixed, bodies, states);
        let r_parent = parent.state.dq.rotate(frame_parent);
        let r_other = other.dq.rotate(frame_other);
        row.c = from_f64(side) * ((parent.state.dp - other.dp) + (r_parent - r_other))
            + point.delta_center;
        (row.r_parent, row.r_other) = (r_parent, r_other);
        row.jac_parent = Jacobian::new(side, r_parent, parent);
        row.impulse = point.impulse;
        row.three = false;
        row.angle_impulse = 0.0;
        if let Some(angle) = tree_angle {
            // C_θ = θ_b − θ_a − θ_ref from the start-of-step value and the
            // rotation deltas since, in the joint's own order (a, b).
            let (q_a, q_b) = if side > 0.0 {
                (other.dq, parent.state.dq)
            } else {
                (parent.state.dq, other.dq)
            };
            row.three = true;
            row.c_angle = wrap_angle(angle.delta_angle + q_a.relative_angle(q_b));
            row.angle_impulse = angle.impulse;
        }
        if correct {
            // Pseudo-impulses start from zero and are not kept.
            row.impulse = Vec2::ZERO;
            row.angle_impulse = 0.0;
        }
        let lambda = wide(row.impulse);
        let parent = &mut bodies[tj.parent as usize];
        parent.leaf = false;
        if correct {
            // The correction's metric: the longest arm (see below).
            parent.geometric = parent.geometric.max(to_f64(r_parent.length_squared()));
        } else {
            parent.geometric += geometric_stiffness(h, lambda, r_parent, side);
        }
        if tj.child != NONE {
            let child = &mut bodies[tj.child as usize];
            child.set_mass(if side > 0.0 {
                base.masses.a
            } else {
                base.masses.b
            });
            row.jac_child = Jacobian::new(-side, r_other, child);
            child.geometric_up = if correct {
                to_f64(r_other.length_squared())
            } else {
                geometric_stiffness(h, lambda, r_other, -side)
            };
        }
    }
    // Ĩ = max(I, K_g / GEOMETRIC_RATIO): only the inertia the limit needs
    // is added. Body pivots start as diag(m, m, Ĩ), placeholder 1 on an
    // axis the body cannot move along.
    for sc in bodies.iter_mut() {
        let inv_i = to_f64(sc.mass.inv_inertia);
        let (mut added, mut inv_i_tilde) = (0.0, inv_i);
        // Its child joints' terms first, then its parent joint's.
        let geometric = sc.geometric + sc.geometric_up;
        if correct {
            // The correction's inertia: at least m r² for the longest arm
            // r (see VELOCITY_CORRECTION_SPEED).
            let arm_squared = CORRECTION_INERTIA * sc.geometric.max(sc.geometric_up);
            let inv_m = to_f64(sc.mass.inv_mass);
            if sc.ang > 0.0 && inv_m > 0.0 {
                added = (arm_squared / inv_m - 1.0 / inv_i).max(0.0);
            }
            if added > 0.0 {
                inv_i_tilde = 1.0 / (1.0 / inv_i + added);
            }
        } else if sc.ang > 0.0 && geometric > 0.0 {
            added = (geometric / GEOMETRIC_RATIO - 1.0 / inv_i).max(0.0);
            if added > 0.0 {
                inv_i_tilde = 1.0 / (1.0 / inv_i + added);
            }
        }
        sc.inertia_change = from_f64(inv_i_tilde - inv_i);
        sc.geometric = added;
        sc.d = body_mass(&sc.mass, added);
        sc.b = DVec3::ZERO;
    }
    if use_bias {
        // The warm start applied the kept impulses through the bodies' own
        // inertia; re-weight their torque to the solve's inertia.
        for ((tj, row), w) in topology.iter().zip(rows.iter()).zip(extra.iter()) {
            if row.general {
                let lambda = wide_rows(w.g_impulse);
                let torque = |j: &Matrix3| from_f64(j.col(2).dot(lambda));
                bodies[tj.parent as usize].reweight_angle(1.0, torque(&w.g_parent));
                if tj.child != NONE {
                    bodies[tj.child as usize].reweight_angle(1.0, torque(&w.g_child));
                }
                continue;
            }
            bodies[tj.parent as usize].reweight(tj.side, row.r_parent, row.impulse);
            if tj.child != NONE {
                bodies[tj.child as usize].reweight(-tj.side, row.r_other, row.impulse);
            }
            if row.three {
                bodies[tj.parent as usize].reweight_angle(tj.side, row.angle_impulse);
                if tj.child != NONE {
                    bodies[tj.child as usize].reweight_angle(-tj.side, row.angle_impulse);
                }
            }
        }
    }
    // Leaves first: each joint's row and pivot, its child body's subtree
    // folded in (that body's pivot is complete: its other joints come
    // later), then the joint folded into its parent body.
    for ((tj, row), w) in topology
        .iter()
        .zip(rows.iter_mut())
        .zip(extra.iter_mut())
        .rev()
    {
        if row.three {
            eliminate_three(tj, row, w, bodies, states, params);
            continue;
        }
        if row.general {
            eliminate_general(tj, row, w, bodies, states, params);
            continue;
        }
        let side = tj.side;
        let (r_parent, r_other) = (row.r_parent, row.r_other);
        let parent = &bodies[tj.parent as usize].state;
        let other = other_end(tj, row.fixed, bodies, states);
        let c_dot = from_f64(side)
            * ((parent.v + cross_sv(parent.w, r_parent)) - (other.v + cross_sv(other.w, r_other)));
        // K in the joint's own order (a, b), as the joint's rows sum it,
        // on the masses its spring is built on.
        let masses = compliance_masses(&row.masses, params);
        let (k11, k12, k22) = if side > 0.0 {
            PointPart::effective_mass(&masses, r_other, r_parent)
        } else {
            PointPart::effective_mass(&masses, r_parent, r_other)
        };
        let (k11, k12, k22) = (to_f64(k11), to_f64(k12), to_f64(k22));
        let rhs = if correct {
            -wide(row.rest)
        } else if use_bias {
            let lambda = wide(row.impulse);
            let held = DVec2::new(
                k11 * lambda.x + k12 * lambda.y,
                k12 * lambda.x + k22 * lambda.y,
            ) * compliance;
            let full = clamp_length(softness.bias_rate * row.c, params.linear_cap());
            let bias = clamp_length(full, velocity_share(from_f64(held.length()), params));
            row.rest = full - bias;
            row.split = bias != full;
            -(wide(c_dot + bias) + held)
        } else {
            -wide(c_dot)
        };
        // D_k = −Γ, Γ = K / a2.
        let mut d = Mat2 {
            m00: -(k11 * compliance),
            m01: -(k12 * compliance),
            m10: -(k12 * compliance),
            m11: -(k22 * compliance),
        };
        let mut b = rhs;
        if tj.child != NONE {
            // D_k −= J D_c⁻¹ Jᵀ,  b_k −= J D_c⁻¹ b_c  (a leaf's b_c is zero).
            let child = &mut bodies[tj.child as usize];
            child.d = pivot_inverse(&child.d);
            let b_c = if child.leaf { None } else { Some(child.b) };
            row.jac_child.fold_body(&child.d, b_c, &mut d, &mut b);
        }
        let t = d.inverse();
        row.d = t;
        row.b = b;
        // D_p −= Jᵀ D_k⁻¹ J,  b_p −= Jᵀ D_k⁻¹ b_k.
        let parent = &mut bodies[tj.parent as usize];
        row.jac_parent
            .fold_joint(&t, b, &mut parent.d, &mut parent.b);
    }
    // Back substitution, root first: x_k = D_k⁻¹ b_k − L_kᵀ x_parent.
    // Each joint's Δλ = −μ is applied as soon as it is known, equal and
    // opposite at its anchors, so linear momentum holds to rounding
    // whatever the pivots' size; the bodies' own Δv is the same change up
    // to the solve's precision. The angular part acts with the inertia the
    // solve used (the body's plus its geometric stiffness term). Fixed ends
    // do not move.
    let root = &mut bodies[0];
    root.d = pivot_inverse(&root.d);
    root.b = root.d * root.b;
    for ((tj, row), w) in topology.iter().zip(rows.iter_mut()).zip(extra.iter_mut()) {
        if row.three {
            substitute_three(tj, row, w, bodies);
            continue;
        }
        if row.general {
            substitute_general(tj, w, bodies);
            continue;
        }
        let side = tj.side;
        let parent = &mut bodies[tj.parent as usize];
        let x = row.jac_parent.joint_solution(&row.d, row.b, parent.b);
        row.b = x;
        let impulse = -Vec2::new(from_f64(x.x), from_f64(x.y));
        let k_linear = row.masses.a.inv_mass + row.masses.b.inv_mass;
        let impulse = bounded_point(&mut row.impulse, impulse, k_linear);
        parent.apply(side, row.r_parent, impulse);
        if tj.child != NONE {
            let child = &mut bodies[tj.child as usize];
            if !child.leaf {
                // A leaf's solution is not needed: no joint below it.
                child.b = row.jac_child.body_solution(&child.d, child.b, x);
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

/// The 3×3 effective mass `K = J M⁻¹ Jᵀ` of a 3-row joint (point rows
/// and angle row) in the joint's own order (a, b), in f64 (see the
/// weld joint's derivation, [`crate::weld`]).
#[inline(always)]
fn three_row_k(m: &PairMass, r_a: Vec2, r_b: Vec2) -> Matrix3 {
    let (k00, k01, k11) = PointPart::effective_mass(m, r_a, r_b);
    let (i_a, i_b) = (to_f64(m.a.inv_inertia), to_f64(m.b.inv_inertia));
    let (r_a, r_b) = (wide(r_a), wide(r_b));
    let k02 = -i_a * r_a.y - i_b * r_b.y;
    let k12 = i_a * r_a.x + i_b * r_b.x;
    let k22 = i_a + i_b;
    let (k00, k01, k11) = (to_f64(k00), to_f64(k01), to_f64(k11));
    Matrix3::from_cols(
        DVec3::new(k00, k01, k02),
        DVec3::new(k01, k11, k12),
        DVec3::new(k02, k12, k22),
    )
}

/// Elimination of a 3-row joint `k` (point rows and angle row), general
/// 3×3 blocks: its row and pivot `D_k = −Γ_k − J_kc D_c⁻¹ J_kcᵀ`,
/// `b_k = r_k − J_kc D_c⁻¹ b_c`, `T = D_k⁻¹`, then folded into its parent
/// body, `D_p −= J_kpᵀ T J_kp`, `b_p −= J_kpᵀ T b_k`.
fn eliminate_three(
    tj: &TreeJoint,
    row: &mut JointScratch,
    w: &mut WideScratch,
    bodies: &mut [BodyScratch],
    states: &[BodyState],
    params: &TreeParams,
) {
    let side = tj.side;
    let (r_parent, r_other) = (row.r_parent, row.r_other);
    let parent = &bodies[tj.parent as usize].state;
    let other = other_end(tj, row.fixed, bodies, states);
    let c_dot = from_f64(side)
        * ((parent.v + cross_sv(parent.w, r_parent)) - (other.v + cross_sv(other.w, r_other)));
    let c_dot_angle = from_f64(side) * (parent.w - other.w);
    let masses = compliance_masses(&row.masses, params);
    let k = if side > 0.0 {
        three_row_k(&masses, r_other, r_parent)
    } else {
        three_row_k(&masses, r_parent, r_other)
    };
    let compliance = params.compliance;
    let softness = params.softness;
    let full = clamp_length(softness.bias_rate * row.c, params.linear_cap());
    let full_angle = cap(
        softness.bias_rate * row.c_angle,
        angular_correction_cap(params.max_correction_speed),
    );
    let rhs = if params.correct {
        let rest = wide(row.rest);
        -DVec3::new(rest.x, rest.y, to_f64(row.rest_angle))
    } else if params.use_bias {
        let lambda = DVec3::new(
            to_f64(row.impulse.x),
            to_f64(row.impulse.y),
            to_f64(row.angle_impulse),
        );
        let held = (k * lambda) * compliance;
        let bias = clamp_length(
            full,
            velocity_share(from_f64(held.truncate().length()), params),
        );
        // Angle rows keep their whole feedback in the velocities: turned
        // on pseudo-velocities, a chain of welds started 3 rad from its
        // reference angles flung its boxes at 87 m/s.
        let bias_angle = full_angle;
        row.rest = full - bias;
        row.rest_angle = 0.0;
        row.split = bias != full;
        let v = wide(c_dot + bias);
        -(DVec3::new(v.x, v.y, to_f64(c_dot_angle + bias_angle)) + held)
    } else {
        let v = wide(c_dot);
        -DVec3::new(v.x, v.y, to_f64(c_dot_angle))
    };
    // D_k = −Γ, Γ = K / a2.
    let mut d = k * -compliance;
    let mut b = rhs;
    if tj.child != NONE {
        // D_k −= J D_c⁻¹ Jᵀ,  b_k −= J D_c⁻¹ b_c  (a leaf's b_c is zero).
        let child = &mut bodies[tj.child as usize];
        child.d = pivot_inverse(&child.d);
        let j = row.jac_child.full();
        let l = j * child.d;
        d -= l * j.transpose();
        if !child.leaf {
            b -= l * child.b;
        }
    }
    let t = pivot_inverse(&d);
    w.d3 = t;
    w.b3 = b;
    // D_p −= Jᵀ D_k⁻¹ J,  b_p −= Jᵀ D_k⁻¹ b_k.
    let parent = &mut bodies[tj.parent as usize];
    let j = row.jac_parent.full();
    let l = j.transpose() * t;
    parent.d -= l * j;
    parent.b -= l * b;
}

/// Back substitution of a 3-row joint `k` from its parent's solution:
/// `x_k = T b_k − T J_kp x_p`, its impulse `Δλ = −x_k` applied (point
/// impulse at the arms, angle impulse as a torque), then its child's
/// `x_c = D_c⁻¹ b_c − D_c⁻¹ J_kcᵀ x_k`.
fn substitute_three(
    tj: &TreeJoint,
    row: &mut JointScratch,
    w: &mut WideScratch,
    bodies: &mut [BodyScratch],
) {
    let side = tj.side;
    let parent = &mut bodies[tj.parent as usize];
    let t = w.d3;
    let x = t * w.b3 - t * (row.jac_parent.full() * parent.b);
    w.b3 = x;
    let m = &row.masses;
    let impulse = bounded_point(
        &mut row.impulse,
        -Vec2::new(from_f64(x.x), from_f64(x.y)),
        m.a.inv_mass + m.b.inv_mass,
    );
    let angular = bounded_sum(
        &mut row.angle_impulse,
        -from_f64(x.z),
        row_bound_of_k(m.a.inv_inertia + m.b.inv_inertia),
    );
    parent.apply(side, row.r_parent, impulse);
    parent.apply_angle(side, angular);
    if tj.child != NONE {
        let child = &mut bodies[tj.child as usize];
        if !child.leaf {
            let s = child.d;
            child.b = s * child.b - s * (row.jac_child.full().transpose() * x);
        }
        child.apply(-side, row.r_other, impulse);
        child.apply_angle(-side, angular);
    }
}

/// `λ += Δλ` for a tree joint's point impulse, its length held within
/// the bound of every kept impulse ([`ROW_SPEED_BOUND`](crate::parts::ROW_SPEED_BOUND),
/// `k_linear = m_a⁻¹ + m_b⁻¹`); returns the change to apply. Within the
/// bound, the plain sum bit for bit: rows that cannot all hold (a body
/// held by a tree joint and by kinematic bodies moving apart) stop growing
/// there instead of overflowing.
#[inline(always)]
fn bounded_point(impulse: &mut Vec2, delta: Vec2, k_linear: Real) -> Vec2 {
    let bound = row_bound_of_k(k_linear);
    let sum = *impulse + delta;
    if sum.length_squared() <= bound * bound {
        *impulse = sum;
        delta
    } else {
        let old = *impulse;
        *impulse = clamp_length(sum, bound);
        *impulse - old
    }
}

/// Three `Real`s as an f64 vector.
#[inline(always)]
fn wide_rows(v: [Real; 3]) -> DVec3 {
    DVec3::new(to_f64(v[0]), to_f64(v[1]), to_f64(v[2]))
}

/// A block of rows on one body as a matrix (rows × (x, y, ω)), each
/// column masked by the body's `lin`/`ang` (a body with the placeholder
/// mass on an axis gets a zero column there); rows past `count` zero.
fn row_block(jr: &[[Real; 3]; 3], count: usize, lin: f64, ang: f64) -> Matrix3 {
    let r = |i: usize| {
        if i < count {
            DVec3::new(
                lin * to_f64(jr[i][0]),
                lin * to_f64(jr[i][1]),
                ang * to_f64(jr[i][2]),
            )
        } else {
            DVec3::ZERO
        }
    };
    Matrix3::from_cols(r(0), r(1), r(2)).transpose()
}

/// `J M⁻¹ Jᵀ` of a block of rows on one body of inverse masses `mass`.
fn block_k(jr: &[[Real; 3]; 3], count: usize, mass: &InvMass) -> Matrix3 {
    let (inv_m, inv_i) = (to_f64(mass.inv_mass), to_f64(mass.inv_inertia));
    let mut k = Matrix3::ZERO;
    for a in 0..count {
        for b in 0..count {
            let linear = to_f64(jr[a][0]) * to_f64(jr[b][0]) + to_f64(jr[a][1]) * to_f64(jr[b][1]);
            let angular = to_f64(jr[a][2]) * to_f64(jr[b][2]);
            k.col_mut(b)[a] += inv_m * linear + inv_i * angular;
        }
    }
    k
}

/// A `General` joint's rows at the tree's current states: the kind builds
/// them in its own order (a, b); the tree keeps them as the parent's and
/// the child's blocks, with `K` from the joint's own masses, and sets the
/// child's mass.
fn general_rows(
    tj: &TreeJoint,
    row: &mut JointScratch,
    w: &mut WideScratch,
    j: &Joint,
    bodies: &mut [BodyScratch],
    states: &[BodyState],
    params: &TreeParams,
) {
    let base = j.base();
    let side = tj.side;
    row.fixed = if side > 0.0 {
        base.state_a
    } else {
        base.state_b
    };
    let parent = bodies[tj.parent as usize].state;
    let other = *other_end(tj, row.fixed, bodies, states);
    let rows: GeneralRows = if side > 0.0 {
        j.tree_general_rows(&other, &parent)
    } else {
        j.tree_general_rows(&parent, &other)
    };
    let count = rows.count.min(3);
    let m = row.masses;
    let (j_parent, j_other, m_parent, m_other) = if side > 0.0 {
        (&rows.j_b, &rows.j_a, m.b, m.a)
    } else {
        (&rows.j_a, &rows.j_b, m.a, m.b)
    };
    w.g_k = block_k(j_parent, count, &m_parent) + block_k(j_other, count, &m_other);
    if params.heavy_inv_mass > 0.0 {
        let spring = compliance_masses(&m, params);
        let (s_parent, s_other) = if side > 0.0 {
            (spring.b, spring.a)
        } else {
            (spring.a, spring.b)
        };
        w.g_k_spring = block_k(j_parent, count, &s_parent) + block_k(j_other, count, &s_other);
    }
    w.g_c = wide_rows(rows.c);
    w.g_impulse = rows.impulse;
    w.g_linear = rows.linear;
    w.g_count = count;
    row.three = false;
    let parent = &mut bodies[tj.parent as usize];
    parent.leaf = false;
    w.g_parent = row_block(j_parent, count, parent.lin, parent.ang);
    w.g_child = if tj.child != NONE {
        let child = &mut bodies[tj.child as usize];
        child.set_mass(m_other);
        row_block(j_other, count, child.lin, child.ang)
    } else {
        // A fixed end: only its velocity enters (through `Ċ`).
        row_block(j_other, count, 1.0, 1.0)
    };
}

/// `J v` of a block of rows on one body's velocity.
#[inline(always)]
fn rows_times(j: &Matrix3, st: &BodyState) -> DVec3 {
    *j * DVec3::new(to_f64(st.v.x), to_f64(st.v.y), to_f64(st.w))
}

/// Elimination of a `General` joint `k` (the general 3×3 blocks of
/// `eliminate_three`, with the kind's rows; unused rows padded with a
/// `−1` pivot and a zero right-hand side, so their solution is zero).
fn eliminate_general(
    tj: &TreeJoint,
    row: &mut JointScratch,
    w: &mut WideScratch,
    bodies: &mut [BodyScratch],
    states: &[BodyState],
    params: &TreeParams,
) {
    let parent = &bodies[tj.parent as usize].state;
    let other = other_end(tj, row.fixed, bodies, states);
    let c_dot = rows_times(&w.g_parent, parent) + rows_times(&w.g_child, other);
    let compliance = params.compliance;
    let mut rhs = if params.correct {
        -w.g_rest
    } else if params.use_bias {
        // Linear rows at the correction speed (m/s), angle rows at its
        // angular counterpart (rad/s); split between the velocity solve
        // and the correction as VELOCITY_CORRECTION_SPEED says.
        let max = to_f64(params.linear_cap());
        let max_angular = to_f64(angular_correction_cap(params.max_correction_speed));
        let held = (w.spring_k(params) * wide_rows(w.g_impulse)) * compliance;
        let mut bias = w.g_c * to_f64(params.softness.bias_rate);
        let clamp = |x: f64, m: f64| {
            if x > m {
                m
            } else if x < -m {
                -m
            } else {
                x
            }
        };
        for (i, linear) in w.g_linear.iter().enumerate() {
            // Angle rows keep their whole feedback in the velocities (see
            // eliminate_three).
            let (max, velocity) = if *linear {
                (max, to_f64(velocity_share(from_f64(held[i].abs()), params)))
            } else {
                (max_angular, f64::MAX)
            };
            let full = clamp(bias[i], max);
            let part = clamp(full, velocity);
            if i < w.g_count && part != full {
                row.split = true;
            }
            w.g_rest[i] = full - part;
            bias[i] = part;
        }
        -(c_dot + bias + held)
    } else {
        -c_dot
    };
    let mut d = w.spring_k(params) * -compliance;
    for i in w.g_count..3 {
        rhs[i] = 0.0;
        d.col_mut(i)[i] = -1.0;
    }
    let mut b = rhs;
    if tj.child != NONE {
        let child = &mut bodies[tj.child as usize];
        child.d = pivot_inverse(&child.d);
        let l = w.g_child * child.d;
        d -= l * w.g_child.transpose();
        if !child.leaf {
            b -= l * child.b;
        }
    }
    let t = pivot_inverse(&d);
    w.d3 = t;
    w.b3 = b;
    let parent = &mut bodies[tj.parent as usize];
    let l = w.g_parent.transpose() * t;
    parent.d -= l * w.g_parent;
    parent.b -= l * b;
}

/// Back substitution of a `General` joint: `x_k = T b_k − T J_kp x_p`,
/// `Δλ = −x_k` applied through each body's block, then the child's
/// `x_c = D_c⁻¹ b_c − D_c⁻¹ J_kcᵀ x_k`.
fn substitute_general(tj: &TreeJoint, w: &mut WideScratch, bodies: &mut [BodyScratch]) {
    let parent = &mut bodies[tj.parent as usize];
    let t = w.d3;
    let x = t * w.b3 - t * (w.g_parent * parent.b);
    w.b3 = x;
    let mut delta = -x;
    for (i, impulse) in w.g_impulse.iter_mut().enumerate().take(w.g_count) {
        let step = from_f64(delta[i]);
        let bound = row_bound_of_k(from_f64(w.g_k.col(i)[i]));
        let applied = bounded_sum(impulse, step, bound);
        if applied != step {
            delta[i] = to_f64(applied);
        }
    }
    parent.apply_rows(&w.g_parent, delta);
    if tj.child != NONE {
        let child = &mut bodies[tj.child as usize];
        if !child.leaf {
            let s = child.d;
            child.b = s * child.b - s * (w.g_child.transpose() * x);
        }
        child.apply_rows(&w.g_child, delta);
    }
}
