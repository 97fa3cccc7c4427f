//! The contact constraint: a non-penetration row per manifold point, with
//! Coulomb friction and restitution.
//!
//! # Derivation
//!
//! For a manifold with unit normal `n` (from a to b), tangent
//! `t = (n.y, −n.x)` and points with anchors `r_a`, `r_b` measured from the
//! centres of mass (fixed on the bodies for the whole step):
//!
//! **Normal row.** `C = s ≥ 0`, the separation along `n`. Its rate is
//! `Ċ = n · (v_b + ω_b × r_b − v_a − ω_a × r_a)`, so
//!
//! ```text
//! J = [ −n  −(r_a × n)   n  (r_b × n) ]
//! k = m_a⁻¹ + m_b⁻¹ + i_a⁻¹ (r_a × n)² + i_b⁻¹ (r_b × n)²
//! ```
//!
//! The separation is refreshed every substep from the position deltas
//! without recomputing the manifold:
//! `s = s₀ + n · ((dp_b − dp_a) + (dq_b r_b − dq_a r_a) − (r_b − r_a))`.
//!
//! - `s > 0` (speculative): `bias = s / h`, rigid — the row only stops the
//!   bodies from closing the gap within the substep.
//! - `s ≤ 0`, with bias: soft push-out `bias = max(β s, −v_push)` with the
//!   contact [`Softness`] (twice the hertz
//!   against static bodies) and the push-out speed cap `v_push`.
//! - relax: no bias, rigid.
//!
//! `λ = −k⁻¹ s_m (Ċ + bias) − s_i λ_acc`, accumulated impulse clamped `≥ 0`.
//!
//! **Mass-ratio-aware softness.** Between two moving bodies the spring of a
//! point is built on the heavier side's effective mass at that point
//! (Softness::with_mass_ratio): with `k_a = m_a⁻¹ + i_a⁻¹ (r_a × n)²` and
//! `k_b` likewise, `k = k_a + k_b` and
//! `ρ = min(k / min(k_a, k_b), ρ_max)`, so `s_m`, `s_i` are per point,
//! computed once in `prepare`. Against a static body `ρ = 1` (that pair
//! already uses the stiffer static softness).
//!
//! **Both normal rows as one block.** One soft row alone is
//! `λ' = s_m (λ − (Ċ + b) / k)` (`λ' = λ + Δλ`, `s_m + s_i = 1`), that is
//! `(k / s_m) λ' = k λ − (Ċ + b)`. A manifold's two points share the
//! bodies, `K = [[k₀₀, k₀₁], [k₀₁, k₁₁]]`; each point keeps its own spring,
//! so the pair solves
//!
//! ```text
//! K' λ' = K λ − (Ċ + b),   K' = [[k₀₀ / s_m0, k₀₁], [k₀₁, k₁₁ / s_m1]]
//! ```
//!
//! exactly (`b` is each point's bias: `s / h` speculative, `max(β s, −v_push)`
//! soft, `max(s / h, 0)` relaxing; `s_m = 1` where rigid). The result is
//! kept where both `λ'` are `≥ 0`; otherwise (a point lifting) and where `K`
//! is ill-conditioned (`k₀₀² ≥ 1000 det K`, nearly redundant points, see
//! `BLOCK_CONDITION`) or the manifold has one point, the normal rows are
//! solved one by one (projected Gauss–Seidel, below). Gauss–Seidel with one
//! iteration per substep leaves the rocking mode of a box on two points
//! half solved; the block removes it (20-row stack: stands 4.9 s point by
//! point, 8.3 s as a block; the heavy-topped pyramids of "high mass ratio
//! 1" hold).
//!
//! **Friction row.** `J` as above with `t` for `n`, no position error;
//! the accumulated impulse is clamped to `±μ λ_n` (Coulomb), with
//! `μ = √(μ_a μ_b)`.
//!
//! **Restitution.** Once after the substeps, for points that approached
//! faster than the threshold: drive `Ċ` to `−e · Ċ_before`, `e = max(e_a, e_b)`.
//!
//! # Evaluation
//!
//! The anchors are kept only through the Jacobian's angular parts
//! `r × n` and `r × t` (computed once, in [`ContactConstraint::new`]):
//! `r · n = −(r × t)`, and for a rotation `dq = (cos, sin)`
//! `n · (dq r) = (r × n) sin − (r × t) cos`, so the separation is
//!
//! ```text
//! s = base + n · (dp_b − dp_a) + ((r_b × n) sin_b − (r_b × t) cos_b)
//!                              − ((r_a × n) sin_a − (r_a × t) cos_a)
//! base = s₀ + (r_b × t) − (r_a × t)
//! ```
//!
//! One iteration solves the rows in the order normal 0, normal 1 (or both
//! as a block), friction 0, friction 1 (projected Gauss–Seidel). It forms every row's
//! `Ċ = J v` once from the loaded velocities and, after row `i`'s
//! increment `Δλ_i`, advances each later row `j` by `K_ij Δλ_i` with
//! `K_ij = J_j M⁻¹ J_iᵀ` (exact in real arithmetic: the velocities move by
//! `M⁻¹ J_iᵀ Δλ_i`); the velocities are written once at the end. The
//! results equal a row-by-row velocity update up to round-off, with a much
//! shorter dependency chain from one row to the next.

use janus2d_core::body::{BodyHandle, BodySet, BodyState, InvMass};
use janus2d_core::constraint::{Block, BodyJacobian, Constraint, ConstraintRows, Row, StepContext};
use janus2d_core::math::{Real, Rot, Vec2, cross};
use janus2d_core::softness::Softness;
use smallvec::smallvec;

use crate::contact_solver::BLOCK_CONDITION;

/// Maximum points per manifold.
pub const MAX_MANIFOLD_POINTS: usize = 2;

/// Rows of a constraint: the normal rows of points 0 and 1, then their
/// friction rows. A one-point manifold leaves rows 1 and 3 at zero (zero
/// Jacobian, mass and impulse), which the solve passes through exactly.
pub(crate) const ROWS: usize = 2 * MAX_MANIFOLD_POINTS;

// The solve is written out for two points (four rows).
const _: () = assert!(MAX_MANIFOLD_POINTS == 2);

/// One point of a contact, as the collision pipeline hands it over.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactPointInput {
    /// Anchor on a relative to a's centre of mass (world frame), m.
    pub anchor_a: Vec2,
    /// Anchor on b relative to b's centre of mass (world frame), m.
    pub anchor_b: Vec2,
    /// Separation along the normal when the manifold was computed, m.
    pub separation: Real,
    /// Normal impulse kept from the last step (warm start), N·s.
    pub normal_impulse: Real,
    /// Tangent impulse kept from the last step (warm start), N·s.
    pub tangent_impulse: Real,
}

/// A contact constraint between two bodies (one manifold, 1–2 points).
///
/// The data is stored by row (normal 0, normal 1, friction 0, friction 1)
/// in a fixed, cache-line aligned layout (`repr(C)`): what the warm start
/// reads (Jacobians, impulses, state indices, normal) fills the first cache
/// line (f32), the rest of what the velocity iterations read the second,
/// and the fields they never touch (handles, restitution data, portal
/// masses) the third. The anchors themselves are not kept: the Jacobian's
/// angular parts determine them, `r = (r × n) t − (r × t) n`.
#[derive(Clone, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct ContactConstraint {
    /// Angular Jacobian parts on a per row: `r_a × n` (rows 0, 1) and
    /// `r_a × t` (rows 2, 3), m.
    pub(crate) ja: [Real; ROWS],
    /// Angular Jacobian parts on b per row: `r_b × n`, `r_b × t`, m.
    pub(crate) jb: [Real; ROWS],
    /// Accumulated impulse per row, N·s.
    pub(crate) impulse: [Real; ROWS],
    /// State index of body a (0: static, sleeping or stale).
    pub(crate) state_a: u32,
    /// State index of body b.
    pub(crate) state_b: u32,
    /// Unit normal from a to b (world).
    pub normal: Vec2,
    /// Rigid effective mass `1 / k` per row, kg.
    pub(crate) mass: [Real; ROWS],
    /// Mixed friction coefficient `√(μ_a μ_b)`.
    pub friction: Real,
    /// Bias rate of the contact softness (static or moving pair), 1/s.
    pub(crate) bias_rate: Real,
    /// `s₀ − n · (r_b − r_a)` per point: the separation at zero position
    /// deltas is `base + (r_a × t) − (r_b × t)`, m.
    pub(crate) base_separation: [Real; MAX_MANIFOLD_POINTS],
    /// Soft effective mass `s_m / k` of each normal row, kg.
    pub(crate) soft_mass: [Real; MAX_MANIFOLD_POINTS],
    /// Soft impulse scale `s_i` of each normal row (dimensionless).
    pub(crate) impulse_scale: [Real; MAX_MANIFOLD_POINTS],
    /// Largest normal impulse applied in one iteration (restitution gate).
    pub(crate) max_normal_impulse: [Real; MAX_MANIFOLD_POINTS],
    /// Number of points (0 to 2).
    pub(crate) point_count: u32,
    /// Diagonal `[k₀₀, k₁₁]` of the normal rows' `K` when the two points
    /// are solved as one block (two points, well conditioned), else zero.
    pub(crate) block_k: [Real; MAX_MANIFOLD_POINTS],
    /// The two normal rows are solved as one block.
    pub(crate) block: bool,
    /// Normal velocity before the solve (for restitution), m/s.
    pub(crate) relative_velocity: [Real; MAX_MANIFOLD_POINTS],
    /// Mixed restitution `max(e_a, e_b)`.
    pub restitution: Real,
    /// Index of the contact in the world's contact list (for storing impulses).
    pub contact_index: u32,
    /// Body a.
    pub body_a: BodyHandle,
    /// Body b.
    pub body_b: BodyHandle,
    /// Inverse masses and inertias the impulses act with, loaded from the
    /// bodies at prepare: `[m_a⁻¹, i_a⁻¹, m_b⁻¹, i_b⁻¹]`.
    pub(crate) applied_masses: [Real; 4],
    /// `Σ λ_warm start − λ_prepare` per row: with the final `λ`, the
    /// impulse of the whole step, N·s (see
    /// [`PointImpulse`](crate::contact_solver::PointImpulse)).
    pub(crate) step_base: [Real; ROWS],
}

/// `max(x, floor)` that returns `floor` when `x` is NaN (as `Real::max`),
/// in one instruction.
#[inline(always)]
fn max_or(x: Real, floor: Real) -> Real {
    if x > floor { x } else { floor }
}

/// `x` clamped to `[lo, hi]` (NaN passes through, as `Real::clamp`),
/// without `Real::clamp`'s `lo ≤ hi` assertion.
#[inline(always)]
fn clamp_to(x: Real, lo: Real, hi: Real) -> Real {
    let x = if x < lo { lo } else { x };
    if x > hi { hi } else { x }
}

/// `Σ x_k y_k` over the rows, as `(x₀y₀ + x₁y₁) + (x₂y₂ + x₃y₃)`.
#[inline(always)]
fn dot_rows(x: &[Real; ROWS], y: &[Real; ROWS]) -> Real {
    (x[0] * y[0] + x[1] * y[1]) + (x[2] * y[2] + x[3] * y[3])
}

impl ContactConstraint {
    /// A constraint from the pipeline's manifold data.
    pub fn new(
        body_a: BodyHandle,
        body_b: BodyHandle,
        normal: Vec2,
        points: &[ContactPointInput],
        friction: Real,
        restitution: Real,
        contact_index: u32,
    ) -> Self {
        let t = Vec2::new(normal.y, -normal.x);
        let mut c = ContactConstraint {
            ja: [0.0; ROWS],
            jb: [0.0; ROWS],
            mass: [0.0; ROWS],
            impulse: [0.0; ROWS],
            state_a: 0,
            state_b: 0,
            normal,
            friction,
            bias_rate: 0.0,
            base_separation: [0.0; MAX_MANIFOLD_POINTS],
            soft_mass: [0.0; MAX_MANIFOLD_POINTS],
            impulse_scale: [0.0; MAX_MANIFOLD_POINTS],
            max_normal_impulse: [0.0; MAX_MANIFOLD_POINTS],
            point_count: points.len().min(MAX_MANIFOLD_POINTS) as u32,
            block_k: [0.0; MAX_MANIFOLD_POINTS],
            block: false,
            relative_velocity: [0.0; MAX_MANIFOLD_POINTS],
            restitution,
            contact_index,
            body_a,
            body_b,
            applied_masses: [0.0; 4],
            step_base: [0.0; ROWS],
        };
        for (i, p) in points.iter().take(MAX_MANIFOLD_POINTS).enumerate() {
            let (r_a, r_b) = (p.anchor_a, p.anchor_b);
            c.ja[i] = cross(r_a, normal);
            c.jb[i] = cross(r_b, normal);
            c.ja[i + 2] = cross(r_a, t);
            c.jb[i + 2] = cross(r_b, t);
            // r · n = −(r × t).
            c.base_separation[i] = p.separation + (c.jb[i + 2] - c.ja[i + 2]);
            c.impulse[i] = p.normal_impulse;
            c.impulse[i + 2] = p.tangent_impulse;
        }
        c
    }

    /// The effective masses and softness of every row from the inverse
    /// masses `k_masses = [m_a⁻¹, i_a⁻¹, m_b⁻¹, i_b⁻¹]` (the bodies' own
    /// at prepare; a whole object's for a portal copy, through the contact
    /// batch's modification hook).
    pub(crate) fn prepare_rows(
        &mut self,
        ctx: &StepContext,
        bodies: &BodySet,
        k_masses: [Real; 4],
    ) {
        let sa = &bodies.states[self.state_a as usize];
        let sb = &bodies.states[self.state_b as usize];
        let [m_a, i_a, m_b, i_b] = k_masses;
        let static_pair = self.applied_masses[0] == 0.0 || self.applied_masses[2] == 0.0;
        let softness = if static_pair {
            ctx.static_softness
        } else {
            ctx.contact_softness
        };
        self.bias_rate = softness.bias_rate;
        let moving_pair = !static_pair;
        let rho_max = ctx.contact_mass_ratio_cap;
        let dv = sb.v - sa.v;
        let dvn = dv.dot(self.normal);
        for i in 0..self.point_count() {
            let (rn_a, rn_b) = (self.ja[i], self.jb[i]);
            let (rt_a, rt_b) = (self.ja[i + 2], self.jb[i + 2]);
            let k_a = m_a + i_a * rn_a * rn_a;
            let k_b = m_b + i_b * rn_b * rn_b;
            let k = k_a + k_b;
            let soft = normal_softness(softness, moving_pair, rho_max, k_a, k_b);
            let normal_mass = if k > 0.0 { 1.0 / k } else { 0.0 };
            self.mass[i] = normal_mass;
            self.soft_mass[i] = normal_mass * soft.mass_scale;
            self.impulse_scale[i] = soft.impulse_scale;
            let k_t = m_a + m_b + i_a * rt_a * rt_a + i_b * rt_b * rt_b;
            self.mass[i + 2] = if k_t > 0.0 { 1.0 / k_t } else { 0.0 };
            self.relative_velocity[i] = dvn + (sb.w * rn_b - sa.w * rn_a);
            self.max_normal_impulse[i] = 0.0;
        }
        // The block of the two normal rows, K = [[k00, k01], [k01, k11]].
        let (ja, jb) = (self.ja, self.jb);
        let k00 = m_a + m_b + i_a * ja[0] * ja[0] + i_b * jb[0] * jb[0];
        let k11 = m_a + m_b + i_a * ja[1] * ja[1] + i_b * jb[1] * jb[1];
        let k01 = m_a + m_b + i_a * ja[0] * ja[1] + i_b * jb[0] * jb[1];
        let det = k00 * k11 - k01 * k01;
        self.block = self.point_count() == 2 && det > 0.0 && k00 * k00 < BLOCK_CONDITION * det;
        self.block_k = if self.block { [k00, k11] } else { [0.0; 2] };
    }

    /// Applies the impulses kept from the last step, `Δv = M⁻¹ Jᵀ λ`.
    pub(crate) fn apply_warm_start(&mut self, states: &mut [BodyState]) {
        let (ia, ib) = (self.state_a as usize, self.state_b as usize);
        let [m_a, i_a, m_b, i_b] = self.applied_masses;
        let lambda = &self.impulse;
        for (base, &l) in self.step_base.iter_mut().zip(lambda) {
            *base += l;
        }
        let p = (lambda[0] + lambda[1]) * self.normal + (lambda[2] + lambda[3]) * self.tangent();
        let (l_a, l_b) = (dot_rows(lambda, &self.ja), dot_rows(lambda, &self.jb));
        let sa = &mut states[ia];
        sa.v -= m_a * p;
        sa.w -= i_a * l_a;
        let sb = &mut states[ib];
        sb.v += m_b * p;
        sb.w += i_b * l_b;
    }

    /// Number of points.
    pub fn point_count(&self) -> usize {
        self.point_count as usize
    }

    /// Accumulated (normal, tangent) impulses of point `i`, N·s.
    pub fn impulses(&self, i: usize) -> (Real, Real) {
        (self.impulse[i], self.impulse[i + MAX_MANIFOLD_POINTS])
    }

    /// The kept and step-total impulses of point `i`.
    #[must_use]
    pub fn point_impulse(&self, i: usize) -> crate::contact_solver::PointImpulse {
        let (n, t) = self.impulses(i);
        crate::contact_solver::PointImpulse {
            normal: n,
            tangent: t,
            total_normal: self.step_base[i] + n,
            total_tangent: self.step_base[i + MAX_MANIFOLD_POINTS] + t,
        }
    }

    #[inline(always)]
    fn tangent(&self) -> Vec2 {
        Vec2::new(self.normal.y, -self.normal.x)
    }

    /// One velocity iteration: the normal rows, then the friction rows,
    /// each a projected Gauss–Seidel step.
    ///
    /// The rows' velocities `Ċ = J v` are formed once from the loaded
    /// velocities; after row `i`'s impulse `Δλ_i` each later row `j`
    /// advances by `K_ij Δλ_i` (`K_ij = J_j M⁻¹ J_iᵀ`: exact in real
    /// arithmetic), and the bodies' velocities are written once,
    /// `Δv = M⁻¹ Jᵀ Δλ`. The Gauss–Seidel dependency chain from one row to
    /// the next is then one multiply-add instead of a velocity update and a
    /// Jacobian product. The parts that do not depend on the velocities
    /// (separation, bias, the feedback `s_i λ`) are formed aside, and the
    /// normal clamp works on the increment, `Δλ = max(λ, −λ_acc)`, so that
    /// `λ_acc + Δλ ≥ 0`.
    #[inline(always)]
    pub(crate) fn solve_rows<const USE_BIAS: bool>(
        &mut self,
        states: &mut [BodyState],
        inv_h: Real,
        push_max: Real,
    ) {
        let (ia, ib) = (self.state_a as usize, self.state_b as usize);
        let (sa, sb) = (&states[ia], &states[ib]);
        let [m_a, i_a, m_b, i_b] = self.applied_masses;
        let (v_a, w_a, v_b, w_b) = (sa.v, sa.w, sb.v, sb.w);
        let (qa, qb) = (sa.dq, sb.dq);
        let n = self.normal;
        let t = Vec2::new(n.y, -n.x);
        let dpn = (sb.dp - sa.dp).dot(n);
        let (ja, jb) = (self.ja, self.jb);

        // Ċ of every row at the loaded velocities.
        let dv = v_b - v_a;
        let (dvn, dvt) = (dv.x * n.x + dv.y * n.y, dv.x * t.x + dv.y * t.y);
        let c0 = dvn + (w_b * jb[0] - w_a * ja[0]);
        let c1 = dvn + (w_b * jb[1] - w_a * ja[1]);
        let c2 = dvt + (w_b * jb[2] - w_a * ja[2]);
        let c3 = dvt + (w_b * jb[3] - w_a * ja[3]);

        // K_ij = J_j M⁻¹ J_iᵀ for i < j (n · t = 0).
        let m_sum = m_a + m_b;
        let (ka0, ka1, ka2) = (i_a * ja[0], i_a * ja[1], i_a * ja[2]);
        let (kb0, kb1, kb2) = (i_b * jb[0], i_b * jb[1], i_b * jb[2]);
        let k01 = m_sum + (ka0 * ja[1] + kb0 * jb[1]);
        let k02 = ka0 * ja[2] + kb0 * jb[2];
        let k03 = ka0 * ja[3] + kb0 * jb[3];
        let k12 = ka1 * ja[2] + kb1 * jb[2];
        let k13 = ka1 * ja[3] + kb1 * jb[3];
        let k23 = m_sum + (ka2 * ja[3] + kb2 * jb[3]);

        // Normal rows: both at once where the block holds, else one by one.
        let (d0, d1) =
            match self.block_normal_rows::<USE_BIAS>(c0, c1, k01, dpn, qa, qb, inv_h, push_max) {
                Some(d) => d,
                None => {
                    let d0 = self.normal_row::<USE_BIAS>(0, c0, dpn, qa, qb, inv_h, push_max);
                    let c1 = c1 + k01 * d0;
                    let d1 = self.normal_row::<USE_BIAS>(1, c1, dpn, qa, qb, inv_h, push_max);
                    (d0, d1)
                }
            };
        // Friction rows.
        let c2 = (c2 + k02 * d0) + k12 * d1;
        let d2 = self.friction_row(2, c2);
        let c3 = ((c3 + k03 * d0) + k13 * d1) + k23 * d2;
        let d3 = self.friction_row(3, c3);

        // The velocities, once: Δv = M⁻¹ Jᵀ Δλ summed over the rows.
        let d = [d0, d1, d2, d3];
        let p = (d0 + d1) * n + (d2 + d3) * t;
        let (l_a, l_b) = (dot_rows(&d, &ja), dot_rows(&d, &jb));
        let ta = &mut states[ia];
        ta.v = v_a - m_a * p;
        ta.w = w_a - i_a * l_a;
        let tb = &mut states[ib];
        tb.v = v_b + m_b * p;
        tb.w = w_b + i_b * l_b;
    }

    /// The terms of point `i`'s normal row: bias `b` (m/s), mass scale
    /// `s_m` and impulse scale `s_i` of `Δλ = −m s_m (Ċ + b) − s_i λ`.
    #[inline(always)]
    pub(crate) fn normal_terms<const USE_BIAS: bool>(
        &self,
        i: usize,
        dpn: Real,
        qa: Rot,
        qb: Rot,
        inv_h: Real,
        push_max: Real,
    ) -> (Real, Real, Real) {
        let (ja, jb) = (&self.ja, &self.jb);
        let s = self.base_separation[i]
            + dpn
            + (qb.s * jb[i] - qb.c * jb[i + 2])
            + (qa.c * ja[i + 2] - qa.s * ja[i]);
        if !USE_BIAS {
            (max_or(s * inv_h, 0.0), 1.0, 0.0)
        } else if s > 0.0 {
            (s * inv_h, 1.0, 0.0)
        } else {
            let is = self.impulse_scale[i];
            (max_or(self.bias_rate * s, -push_max), 1.0 - is, is)
        }
    }

    /// Both normal rows at once (see the module docs): `None` where the
    /// manifold has no block or either accumulated impulse would go
    /// negative (then Gauss–Seidel takes the points one by one).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn block_normal_rows<const USE_BIAS: bool>(
        &mut self,
        c0: Real,
        c1: Real,
        k01: Real,
        dpn: Real,
        qa: Rot,
        qb: Rot,
        inv_h: Real,
        push_max: Real,
    ) -> Option<(Real, Real)> {
        if !self.block {
            return None;
        }
        let (b0, ms0, _) = self.normal_terms::<USE_BIAS>(0, dpn, qa, qb, inv_h, push_max);
        let (b1, ms1, _) = self.normal_terms::<USE_BIAS>(1, dpn, qa, qb, inv_h, push_max);
        let [k00, k11] = self.block_k;
        let (old0, old1) = (self.impulse[0], self.impulse[1]);
        let q0 = (c0 + b0) - (k00 * old0 + k01 * old1);
        let q1 = (c1 + b1) - (k01 * old0 + k11 * old1);
        let (kp00, kp11) = (k00 / ms0, k11 / ms1);
        let inv_det = 1.0 / (kp00 * kp11 - k01 * k01);
        let x0 = (k01 * q1 - kp11 * q0) * inv_det;
        let x1 = (k01 * q0 - kp00 * q1) * inv_det;
        if !(x0 >= 0.0 && x1 >= 0.0) {
            return None;
        }
        let (d0, d1) = (x0 - old0, x1 - old1);
        self.impulse[0] = x0;
        self.impulse[1] = x1;
        self.max_normal_impulse[0] = max_or(d0, self.max_normal_impulse[0]);
        self.max_normal_impulse[1] = max_or(d1, self.max_normal_impulse[1]);
        Some((d0, d1))
    }

    /// The normal row of point `i` given its `Ċ`: accumulates the impulse
    /// and returns the increment.
    #[inline(always)]
    fn normal_row<const USE_BIAS: bool>(
        &mut self,
        i: usize,
        c_dot: Real,
        dpn: Real,
        qa: Rot,
        qb: Rot,
        inv_h: Real,
        push_max: Real,
    ) -> Real {
        let (ja, jb) = (&self.ja, &self.jb);
        // Current separation from the deltas, anchors fixed on the bodies:
        // n · (dq r) = (r × n) sin − (r × t) cos.
        let s = self.base_separation[i]
            + dpn
            + (qb.s * jb[i] - qb.c * jb[i + 2])
            + (qa.c * ja[i + 2] - qa.s * ja[i]);
        let old = self.impulse[i];
        let rigid = self.mass[i];
        // λ = offset − mass · Ċ.
        let (mass, offset) = if USE_BIAS {
            if s > 0.0 {
                (rigid, -(rigid * (s * inv_h)))
            } else {
                let soft = self.soft_mass[i];
                let bias = max_or(self.bias_rate * s, -push_max);
                (soft, -(soft * bias) - self.impulse_scale[i] * old)
            }
        } else {
            (rigid, -(rigid * max_or(s * inv_h, 0.0)))
        };
        let d = max_or(offset - mass * c_dot, -old);
        self.impulse[i] = old + d;
        self.max_normal_impulse[i] = max_or(d, self.max_normal_impulse[i]);
        d
    }

    /// The friction rows alone, one by one, from the bodies' velocities
    /// (after a coupled group has solved the normal rows).
    pub(crate) fn solve_friction_rows(&mut self, states: &mut [BodyState]) {
        let (ia, ib) = (self.state_a as usize, self.state_b as usize);
        let [m_a, i_a, m_b, i_b] = self.applied_masses;
        let t = self.tangent();
        for i in 0..self.point_count() {
            let row = i + MAX_MANIFOLD_POINTS;
            let (sa, sb) = (&states[ia], &states[ib]);
            let c_dot = (sb.v - sa.v).dot(t) + (sb.w * self.jb[row] - sa.w * self.ja[row]);
            let d = self.friction_row(row, c_dot);
            let p = d * t;
            states[ia].v -= m_a * p;
            states[ia].w -= i_a * d * self.ja[row];
            states[ib].v += m_b * p;
            states[ib].w += i_b * d * self.jb[row];
        }
    }

    /// Stiffens the normal rows of a contact of a light cluster's group:
    /// each row's spring is built on the effective mass it would have if
    /// every side in the cluster (`in_cluster`) had the inverse mass and
    /// inertia `heavy = [m_H⁻¹, i_H⁻¹]` of the heaviest body the cluster
    /// touches (`contact_group` docs), where that is stiffer than the row's
    /// own spring.
    pub(crate) fn stiffen_for_group(
        &mut self,
        ctx: &StepContext,
        in_cluster: [bool; 2],
        k_masses: [Real; 4],
        heavy: [Real; 2],
    ) {
        let [m_a, i_a, m_b, i_b] = k_masses;
        let static_pair = m_a == 0.0 || m_b == 0.0;
        let softness = if static_pair {
            ctx.static_softness
        } else {
            ctx.contact_softness
        };
        let [m_h, i_h] = heavy;
        for i in 0..self.point_count() {
            let (rn_a, rn_b) = (self.ja[i], self.jb[i]);
            let k_a = m_a + i_a * rn_a * rn_a;
            let k_b = m_b + i_b * rn_b * rn_b;
            let k_group_a = if in_cluster[0] {
                m_h + i_h * rn_a * rn_a
            } else {
                k_a
            };
            let k_group_b = if in_cluster[1] {
                m_h + i_h * rn_b * rn_b
            } else {
                k_b
            };
            let k_group = k_group_a + k_group_b;
            if k_group <= 0.0 {
                continue;
            }
            let rho_group = (k_a + k_b) / k_group;
            let soft = softness.with_mass_ratio(rho_group);
            if soft.impulse_scale < self.impulse_scale[i] {
                self.impulse_scale[i] = soft.impulse_scale;
                self.soft_mass[i] = self.mass[i] * soft.mass_scale;
            }
        }
    }

    /// Friction row `i` (2 or 3) given its `Ċ`: accumulates the impulse,
    /// bounded by `±μ λ_n` of its point, and returns the increment.
    #[inline(always)]
    fn friction_row(&mut self, i: usize, c_dot: Real) -> Real {
        let old = self.impulse[i];
        let max_friction = self.friction * self.impulse[i - MAX_MANIFOLD_POINTS];
        let neg_mass = -self.mass[i];
        let d = clamp_to(neg_mass * c_dot, -max_friction - old, max_friction - old);
        self.impulse[i] = clamp_to(old + d, -max_friction, max_friction);
        d
    }
}

/// The softness of one normal row: the contact softness scaled by the
/// mass ratio `ρ = min(k / min(k_a, k_b), ρ_max)` of the point's two
/// effective masses (1 for a pair with a static body). Used by the solve
/// and reported by `rows()`.
fn normal_softness(
    softness: Softness,
    moving_pair: bool,
    rho_max: Real,
    k_a: Real,
    k_b: Real,
) -> Softness {
    let k = k_a + k_b;
    let k_heavy = k_a.min(k_b);
    let rho = if moving_pair && rho_max > 1.0 && k_heavy > 0.0 {
        (k / k_heavy).min(rho_max)
    } else {
        1.0
    };
    softness.with_mass_ratio(rho)
}

impl Constraint for ContactConstraint {
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        // Static, sleeping and stale bodies read the identity state 0.
        self.state_a = bodies.state_index(self.body_a).unwrap_or(0);
        self.state_b = bodies.state_index(self.body_b).unwrap_or(0);
        let ma = bodies.inv_masses_at(self.state_a);
        let mb = bodies.inv_masses_at(self.state_b);
        self.applied_masses = [ma.inv_mass, ma.inv_inertia, mb.inv_mass, mb.inv_inertia];
        self.prepare_rows(ctx, bodies, self.applied_masses);
        if !ctx.warm_starting {
            self.impulse = [0.0; ROWS];
        }
        self.step_base = self.impulse.map(|l| -l);
    }

    fn warm_start(&mut self, _ctx: &StepContext, states: &mut [BodyState]) {
        self.apply_warm_start(states);
    }

    fn solve(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        let (inv_h, push_max) = (ctx.inv_h, ctx.contact_push_max_velocity);
        if use_bias {
            self.solve_rows::<true>(states, inv_h, push_max);
        } else {
            self.solve_rows::<false>(states, inv_h, push_max);
        }
    }

    fn apply_restitution(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        if self.restitution == 0.0 {
            return;
        }
        let (ia, ib) = (self.state_a as usize, self.state_b as usize);
        let (sa, sb) = (&states[ia], &states[ib]);
        let [m_a, i_a, m_b, i_b] = self.applied_masses;
        let (mut v_a, mut w_a, mut v_b, mut w_b) = (sa.v, sa.w, sb.v, sb.w);
        let n = self.normal;
        let e = self.restitution;
        for i in 0..self.point_count() {
            let rv = self.relative_velocity[i];
            if rv > -ctx.restitution_threshold || self.max_normal_impulse[i] == 0.0 {
                continue;
            }
            let (rn_a, rn_b) = (self.ja[i], self.jb[i]);
            let c_dot = (v_b - v_a).dot(n) + (w_b * rn_b - w_a * rn_a);
            let lambda = -self.mass[i] * (c_dot + e * rv);
            let old = self.impulse[i];
            let new_impulse = (old + lambda).max(0.0);
            let applied = new_impulse - old;
            self.impulse[i] = new_impulse;
            self.max_normal_impulse[i] = self.max_normal_impulse[i].max(applied);
            let p = applied * n;
            v_a -= m_a * p;
            w_a -= i_a * applied * rn_a;
            v_b += m_b * p;
            w_b += i_b * applied * rn_b;
        }
        let ta = &mut states[ia];
        ta.v = v_a;
        ta.w = w_a;
        let tb = &mut states[ib];
        tb.v = v_b;
        tb.w = w_b;
    }

    fn rows(&self, ctx: &StepContext, bodies: &BodySet) -> ConstraintRows {
        let a = bodies.solver_body(self.body_a);
        let b = bodies.solver_body(self.body_b);
        let (sa, sb) = (a.inv_masses(), b.inv_masses());
        let static_pair = sa.inv_mass == 0.0 || sb.inv_mass == 0.0;
        let softness = if static_pair {
            ctx.static_softness
        } else {
            ctx.contact_softness
        };
        let mut out = ConstraintRows::default();
        let entry = |body, linear: Vec2, angular, s: &InvMass| BodyJacobian {
            body,
            linear,
            angular,
            inv_mass: s.inv_mass,
            inv_inertia: s.inv_inertia,
        };
        let count = self.point_count();
        for (axis, first) in [(self.normal, 0), (self.tangent(), MAX_MANIFOLD_POINTS)] {
            for i in 0..count {
                let row = first + i;
                let first_row = out.rows.len();
                let (j_a, j_b) = (self.ja[row], self.jb[row]);
                let (c, softness, lower, upper) = if first == 0 {
                    // At the start of the step: r · n = −(r × t).
                    let s = self.base_separation[i] - (self.jb[i + 2] - self.ja[i + 2]);
                    let k_a = sa.inv_mass + sa.inv_inertia * j_a * j_a;
                    let k_b = sb.inv_mass + sb.inv_inertia * j_b * j_b;
                    let soft = normal_softness(
                        softness,
                        !static_pair,
                        ctx.contact_mass_ratio_cap,
                        k_a,
                        k_b,
                    );
                    (s, soft, 0.0, Real::INFINITY)
                } else {
                    let m = self.friction * self.impulse[i];
                    (0.0, Softness::RIGID, -m, m)
                };
                out.rows.push(Row {
                    jacobian: smallvec![
                        entry(self.body_a, -axis, -j_a, &sa),
                        entry(self.body_b, axis, j_b, &sb),
                    ],
                    c,
                    softness,
                    lower,
                    upper,
                    impulse: self.impulse[row],
                });
                let k = sa.inv_mass
                    + sb.inv_mass
                    + sa.inv_inertia * j_a * j_a
                    + sb.inv_inertia * j_b * j_b;
                out.blocks.push(Block {
                    first_row,
                    len: 1,
                    k: [[k, 0.0, 0.0], [0.0; 3], [0.0; 3]],
                });
            }
        }
        out
    }
}

/// Mixes two friction coefficients: `√(μ_a μ_b)`.
#[inline]
pub fn mix_friction(a: Real, b: Real) -> Real {
    (a * b).sqrt()
}

/// Mixes two restitution coefficients: `max(e_a, e_b)`.
#[inline]
pub fn mix_restitution(a: Real, b: Real) -> Real {
    a.max(b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use janus2d_core::body::BodyDef;
    use janus2d_core::solver::SolverSettings;

    #[test]
    fn rows_report_the_mass_ratio_softness_the_solve_uses() {
        let mut set = BodySet::new();
        let a = set
            .create(&BodyDef::dynamic(Vec2::ZERO).with_mass(1.0, 0.1))
            .unwrap();
        let b = set
            .create(&BodyDef::dynamic(Vec2::new(0.0, 1.0)).with_mass(1000.0, 100.0))
            .unwrap();
        let settings = SolverSettings::default();
        let ctx = settings.context(1.0 / 60.0, Vec2::ZERO);
        let point = ContactPointInput {
            anchor_a: Vec2::new(0.1, 0.5),
            anchor_b: Vec2::new(0.1, -0.5),
            separation: -0.01,
            normal_impulse: 0.0,
            tangent_impulse: 0.0,
        };
        let mut c = ContactConstraint::new(a, b, Vec2::Y, &[point], 0.6, 0.0, 0);
        c.prepare(&ctx, &set);
        let rows = c.rows(&ctx, &set);
        let normal = rows.rows[0].softness;
        assert_ne!(normal, ctx.contact_softness, "1:1000 is softened");
        // The solve's scaled mass and impulse scale come from the same softness.
        assert_eq!(c.soft_mass[0], c.mass[0] * normal.mass_scale);
        assert_eq!(c.impulse_scale[0], normal.impulse_scale);
    }
}
