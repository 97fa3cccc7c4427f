//! The contact rows, written once: a non-penetration row per manifold
//! point, with Coulomb friction and restitution, generic over the lane
//! type ([`Lane`]). The scalar overflow ([`ContactConstraint`], `L =
//! Real`), the colours' SIMD chunks (`contact_solver`, `L = Wide`,
//! [`LANES`] contacts at a time) and the light clusters' groups
//! ([`crate::contact_group`]: the bias and friction rows) all run these
//! functions; they only load the bodies' states into lanes and store the
//! velocities back.
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
//! - `s > 0` (speculative): `b = s / h`, rigid — the row only stops the
//!   bodies from closing the gap within the substep.
//! - `s ≤ 0`, with bias: soft push-out `b = max(β s, −v_push)` with the
//!   contact [`Softness`] (twice the hertz against static bodies) and the
//!   push-out speed cap `v_push`.
//! - relax: no bias, rigid, `b = max(s / h, 0)`.
//!
//! `Δλ = −s_m k⁻¹ (Ċ + b) − s_i λ` ([`soft_impulse`]), the accumulated
//! impulse clamped `≥ 0`; `s_m = 1 − s_i` (`s_m = 1`, `s_i = 0` where
//! rigid).
//!
//! **Mass-ratio-aware softness.** Between two moving bodies the spring of a
//! point is built on the heavier side's effective mass at that point
//! (`Softness::with_mass_ratio`): with `k_a = m_a⁻¹ + i_a⁻¹ (r_a × n)²` and
//! `k_b` likewise, `k = k_a + k_b` and
//! `ρ = min(k / min(k_a, k_b), ρ_max)`, so `s_i` (and `s_m = 1 − s_i`) is
//! per point, computed once in `prepare`:
//! `s_i = 1 / (1 + ρ a₂)`, `a₂ = s_m / s_i` of the contact softness. Against
//! a static body `ρ = 1` (that pair already uses the stiffer static
//! softness).
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
//! exactly. The result is kept where both `λ'` are `≥ 0`; otherwise (a
//! point lifting) and where `K` is ill-conditioned (`k₀₀² ≥ 1000 det K`,
//! nearly redundant points, see [`BLOCK_CONDITION`]) or the manifold has
//! one point, the normal rows are solved one by one (projected
//! Gauss–Seidel). Gauss–Seidel with one iteration per substep leaves the
//! rocking mode of a box on two points half solved; the block removes it
//! (20-row stack: stands 4.9 s point by point, 8.3 s as a block; the
//! heavy-topped pyramids of "high mass ratio 1" hold). Both are computed
//! and one is selected per lane.
//!
//! **Friction row.** `J` as above with `t` for `n`, no position error;
//! the accumulated impulse is clamped to `±μ λ_n` (Coulomb), with
//! `μ = √(μ_a μ_b)`.
//!
//! **Restitution.** Once after the substeps, for points that approached
//! faster than the threshold and pushed: drive `Ċ` to `−e · Ċ_before`,
//! `e = max(e_a, e_b)`.
//!
//! **Surface rows** (only where a contact has them: `SurfaceRows`).
//! *Tangent speed* `v_t` (a conveyor belt): each friction row drives
//! `Ċ_t − v_t` to zero instead of `Ċ_t`, so the bodies slide relative to
//! each other at `v_t` along `t` while friction holds (the impulse bound
//! is Coulomb's as before). *Rolling resistance*: one angular row per
//! contact, `J = [0  −1  0  1]` (`Ċ = ω_b − ω_a`),
//! `k = i_a⁻¹ + i_b⁻¹`, its accumulated impulse clamped to
//! `±c r (λ_n0 + λ_n1)` with `c r` the mixed rolling resistance times the
//! rolling radius (Box2D v3.1's `rollingResistance`). On flat ground the
//! row's torque `c r N` (`N = m g`) slows a ball of radius `r` rolling
//! without slipping at `a = c g r² / (r² + I/m)` (friction slows its
//! centre with it), `⅔ c g` for a disc, so it stops within
//! `v₀² / (2 a)`. It is solved after the friction rows and warm started
//! within the step (its impulse starts from zero at each step).
//!
//! # Evaluation
//!
//! The anchors are kept only through the Jacobian's angular parts
//! `r × n` and `r × t` (computed once, when a contact is written into its
//! lane): `r · n = −(r × t)`, and for a rotation `dq = (cos, sin)`
//! `n · (dq r) = (r × n) sin − (r × t) cos`, so the separation is
//!
//! ```text
//! s = base + n · (dp_b − dp_a) + ((r_b × n) sin_b − (r_b × t) cos_b)
//!                              − ((r_a × n) sin_a − (r_a × t) cos_a)
//! base = s₀ + (r_b × t) − (r_a × t)
//! ```
//!
//! One iteration solves the rows in the order normal 0, normal 1 (or both
//! as a block), friction 0, friction 1 (projected Gauss–Seidel). It forms
//! every row's `Ċ = J v` once from the loaded velocities and, after row
//! `i`'s increment `Δλ_i`, advances each later row `j` by `K_ij Δλ_i` with
//! `K_ij = J_j M⁻¹ J_iᵀ` (exact in real arithmetic: the velocities move by
//! `M⁻¹ J_iᵀ Δλ_i`); the velocities are written once at the end. The
//! results equal a row-by-row velocity update up to round-off, with a much
//! shorter dependency chain from one row to the next. The normal clamp
//! works on the increment, `Δλ = max(Δλ, −λ)`, so that `λ + Δλ ≥ 0`.
//!
//! Every operation is the same on both lane types (see [`crate::lane`]), so
//! a contact gives the same result in the overflow as in a chunk, up to the
//! sign of a zero.
//!
//! [`ContactConstraint`]: crate::contact::ContactConstraint
//! [`LANES`]: crate::lane::LANES

use janus2d_core::constraint::StepContext;
use janus2d_core::math::{Real, Vec2, cross};
use janus2d_core::softness::Softness;

use crate::lane::Lane;
use crate::parts::soft_impulse;
pub use janus2d_core::contact_input::{ContactPointInput, MAX_MANIFOLD_POINTS};

/// The impulses of one manifold point after a step, N·s.
///
/// `normal` and `tangent` are the accumulated impulses kept for the next
/// step's warm start (what one substep applies). The totals are what the
/// whole step applied: every warm start re-applies the kept impulse, and
/// every solve, relax and restitution increment adds to it, so
///
/// ```text
/// total = Σ_substeps λ_warm start + (λ_end − λ_prepare)
/// ```
///
/// which a lane keeps as `step_base = Σ λ_warm start − λ_prepare` (added to
/// at warm start only, never in the solve loop) plus the final `λ`. A box
/// of mass `m` resting on the ground reads a total normal impulse of
/// `m g dt` for any substep count.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointImpulse {
    /// Accumulated normal impulse (warm start), N·s.
    pub normal: Real,
    /// Accumulated tangent impulse (warm start), N·s.
    pub tangent: Real,
    /// Normal impulse applied over the whole step, N·s.
    pub total_normal: Real,
    /// Tangent impulse applied over the whole step, N·s.
    pub total_tangent: Real,
}

/// Rows of a contact: the normal rows of points 0 and 1, then their
/// friction rows. A one-point manifold leaves rows 1 and 3 at zero (zero
/// Jacobian, mass and impulse), which the solve passes through exactly.
pub(crate) const ROWS: usize = 2 * MAX_MANIFOLD_POINTS;

// The solve is written out for two points (four rows).
const _: () = assert!(MAX_MANIFOLD_POINTS == 2);

/// Largest condition number `k₀₀² / det K` at which a manifold's two normal
/// rows are solved as one block (Box2D v2.4's block solver uses the same
/// bound); above it the points are nearly redundant and Gauss–Seidel takes
/// them one by one.
pub const BLOCK_CONDITION: Real = 1000.0;

pub(crate) use crate::lane::{Delta, Velocity};

/// The rows of one contact (`L = Real`) or of [`LANES`](crate::lane::LANES)
/// contacts (`L = Wide`, structure of arrays): everything the prepare,
/// warm start, solve and restitution read and write. Rows 0, 1 are the
/// normal rows of points 0 and 1, rows 2, 3 their friction rows.
///
/// The fields the warm start reads come first (with `f32`, the first cache
/// line of a scalar contact).
#[derive(Clone, Debug, PartialEq)]
#[repr(C)]
pub(crate) struct ContactRows<L: Lane> {
    /// Angular Jacobian parts on a per row: `r_a × n` (rows 0, 1) and
    /// `r_a × t` (rows 2, 3), m.
    pub(crate) ja: [L; ROWS],
    /// Angular Jacobian parts on b per row: `r_b × n`, `r_b × t`, m.
    pub(crate) jb: [L; ROWS],
    /// Accumulated impulse per row, N·s.
    pub(crate) impulse: [L; ROWS],
    /// Unit normal from a to b, x.
    pub(crate) n_x: L,
    /// Unit normal from a to b, y.
    pub(crate) n_y: L,
    /// Inverse mass of a the impulses act with, 1/kg.
    pub(crate) inv_mass_a: L,
    /// Inverse inertia of a the impulses act with, 1/(kg·m²).
    pub(crate) inv_inertia_a: L,
    /// Inverse mass of b the impulses act with, 1/kg.
    pub(crate) inv_mass_b: L,
    /// Inverse inertia of b the impulses act with, 1/(kg·m²).
    pub(crate) inv_inertia_b: L,
    /// Rigid effective mass `1 / k` per row, kg.
    pub(crate) mass: [L; ROWS],
    /// Mixed friction coefficient `√(μ_a μ_b)`.
    pub(crate) friction: L,
    /// Bias rate of the contact softness (static or moving pair), 1/s.
    pub(crate) bias_rate: L,
    /// `s₀ − n · (r_b − r_a)` per point: the separation at zero position
    /// deltas, m.
    pub(crate) base_separation: [L; MAX_MANIFOLD_POINTS],
    /// Soft impulse scale `s_i` of each normal row (its mass scale is
    /// `1 − s_i`).
    pub(crate) impulse_scale: [L; MAX_MANIFOLD_POINTS],
    /// Diagonal `[k₀₀, k₁₁]` of the two normal rows' `K`, 1/kg.
    pub(crate) block_k: [L; MAX_MANIFOLD_POINTS],
    /// The two normal rows are solved as one block (two points and a
    /// well-conditioned `K`).
    pub(crate) block: L::Mask,
    /// Largest normal impulse increment (restitution gate), N·s.
    pub(crate) max_normal_impulse: [L; MAX_MANIFOLD_POINTS],
    /// Normal velocity of each point before the solve (restitution), m/s.
    pub(crate) relative_velocity: [L; MAX_MANIFOLD_POINTS],
    /// Mixed restitution `max(e_a, e_b)`.
    pub(crate) restitution: L,
    /// `Σ λ_warm start − λ_prepare` per row: with the final `λ`, the
    /// impulse of the whole step, N·s (see
    /// [`PointImpulse`](crate::contact_solver::PointImpulse)).
    pub(crate) step_base: [L; ROWS],
    /// The surface rows (tangent speed, rolling resistance) when some lane
    /// has them; `None` otherwise, and the solve then runs exactly the rows
    /// above (a scene without surface materials pays one test per chunk).
    pub(crate) surface: Option<Box<SurfaceRows<L>>>,
}

/// The surface terms of the lanes' contacts (module docs, Surface rows):
/// kept apart from [`ContactRows`] and only where some lane has them, so
/// that contacts without them carry none of it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SurfaceRows<L: Lane> {
    /// Target relative tangent speed of the friction rows, m/s.
    pub(crate) tangent_speed: L,
    /// Bound of the rolling row per unit normal impulse (rolling
    /// resistance × rolling radius), m.
    pub(crate) rolling_resistance: L,
    /// Effective mass of the rolling row `1 / (i_a⁻¹ + i_b⁻¹)`, kg·m².
    pub(crate) rolling_mass: L,
    /// Accumulated rolling impulse, N·m·s.
    pub(crate) rolling_impulse: L,
}

impl<L: Lane> SurfaceRows<L> {
    /// Every lane without surface terms.
    fn empty() -> Self {
        let z = L::splat(0.0);
        SurfaceRows {
            tangent_speed: z,
            rolling_resistance: z,
            rolling_mass: z,
            rolling_impulse: z,
        }
    }
}

/// Impulses summed over a contact's rows, as they act on its bodies:
/// `p = (λ₀ + λ₁) n + (λ₂ + λ₃) t` (N·s) and the angular impulses
/// `l_a = Σ λ_k (r_a × ·)_k`, `l_b` likewise (N·m·s).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Push<L> {
    p_x: L,
    p_y: L,
    l_a: L,
    l_b: L,
}

/// `Σ x_k y_k` over the rows, as `(x₀y₀ + x₁y₁) + (x₂y₂ + x₃y₃)`.
#[inline(always)]
fn dot_rows<L: Lane>(x: &[L; ROWS], y: &[L; ROWS]) -> L {
    (x[0] * y[0] + x[1] * y[1]) + (x[2] * y[2] + x[3] * y[3])
}

impl<L: Lane> ContactRows<L> {
    /// All zero: every lane a padding lane (zero masses and Jacobians).
    pub(crate) fn empty() -> Self {
        let z = L::splat(0.0);
        ContactRows {
            ja: [z; ROWS],
            jb: [z; ROWS],
            impulse: [z; ROWS],
            n_x: z,
            n_y: z,
            inv_mass_a: z,
            inv_inertia_a: z,
            inv_mass_b: z,
            inv_inertia_b: z,
            mass: [z; ROWS],
            friction: z,
            bias_rate: z,
            base_separation: [z; MAX_MANIFOLD_POINTS],
            impulse_scale: [z; MAX_MANIFOLD_POINTS],
            block_k: [z; MAX_MANIFOLD_POINTS],
            block: z.gt(z),
            max_normal_impulse: [z; MAX_MANIFOLD_POINTS],
            relative_velocity: [z; MAX_MANIFOLD_POINTS],
            restitution: z,
            step_base: [z; ROWS],
            surface: None,
        }
    }

    /// Writes lane `k`'s surface terms: the friction rows' target tangent
    /// speed (m/s) and the rolling row's bound per unit normal impulse
    /// (m). Nothing is written (nor allocated) when both are zero.
    pub(crate) fn set_surface(&mut self, k: usize, tangent_speed: Real, rolling_resistance: Real) {
        if tangent_speed == 0.0 && rolling_resistance == 0.0 {
            return;
        }
        let s = self
            .surface
            .get_or_insert_with(|| Box::new(SurfaceRows::empty()));
        s.tangent_speed.set_lane(k, tangent_speed);
        s.rolling_resistance.set_lane(k, rolling_resistance);
    }

    /// Writes a manifold into lane `k`: the Jacobian's angular parts from
    /// the anchors, the separation at zero deltas (`r · n = −(r × t)`), the
    /// kept impulses, the mixed coefficients and the inverse masses
    /// `[m_a⁻¹, i_a⁻¹, m_b⁻¹, i_b⁻¹]` the impulses act with.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn set_lane(
        &mut self,
        k: usize,
        normal: Vec2,
        points: &[ContactPointInput],
        friction: Real,
        restitution: Real,
        inv_masses: [Real; 4],
    ) {
        let [m_a, i_a, m_b, i_b] = inv_masses;
        self.inv_mass_a.set_lane(k, m_a);
        self.inv_inertia_a.set_lane(k, i_a);
        self.inv_mass_b.set_lane(k, m_b);
        self.inv_inertia_b.set_lane(k, i_b);
        let n = normal;
        let t = Vec2::new(n.y, -n.x);
        self.n_x.set_lane(k, n.x);
        self.n_y.set_lane(k, n.y);
        self.friction.set_lane(k, friction);
        self.restitution.set_lane(k, restitution);
        for (i, p) in points.iter().take(MAX_MANIFOLD_POINTS).enumerate() {
            let (r_a, r_b) = (p.anchor_a, p.anchor_b);
            let (rt_a, rt_b) = (cross(r_a, t), cross(r_b, t));
            self.ja[i].set_lane(k, cross(r_a, n));
            self.jb[i].set_lane(k, cross(r_b, n));
            self.ja[i + 2].set_lane(k, rt_a);
            self.jb[i + 2].set_lane(k, rt_b);
            // r · n = −(r × t).
            self.base_separation[i].set_lane(k, p.separation + (rt_b - rt_a));
            self.impulse[i].set_lane(k, p.normal_impulse);
            self.impulse[i + 2].set_lane(k, p.tangent_impulse);
        }
        // A one-point manifold's second point as in an empty chunk (a
        // reused chunk holds an earlier lane's there).
        for i in points.len().min(MAX_MANIFOLD_POINTS)..MAX_MANIFOLD_POINTS {
            self.clear_point(k, i);
        }
    }

    /// Point `i` of lane `k`'s inputs zero: its Jacobians, kept impulses
    /// and separation.
    #[inline(always)]
    fn clear_point(&mut self, k: usize, i: usize) {
        for row in [i, i + 2] {
            self.ja[row].set_lane(k, 0.0);
            self.jb[row].set_lane(k, 0.0);
            self.impulse[row].set_lane(k, 0.0);
        }
        self.base_separation[i].set_lane(k, 0.0);
    }

    /// Lane `k` as in [`ContactRows::empty`]: every input
    /// [`ContactRows::set_lane`] writes zero (the prepare computes the
    /// other rows from them).
    pub(crate) fn clear_lane(&mut self, k: usize) {
        for field in [
            &mut self.n_x,
            &mut self.n_y,
            &mut self.inv_mass_a,
            &mut self.inv_inertia_a,
            &mut self.inv_mass_b,
            &mut self.inv_inertia_b,
            &mut self.friction,
            &mut self.restitution,
        ] {
            field.set_lane(k, 0.0);
        }
        for i in 0..MAX_MANIFOLD_POINTS {
            self.clear_point(k, i);
        }
    }

    /// Effective masses, the 2×2 normal block and its condition test, the
    /// mass-ratio softness of each normal row and the approach speeds,
    /// with the inverse masses `k_masses = [m_a⁻¹, i_a⁻¹, m_b⁻¹, i_b⁻¹]`
    /// (those the impulses act with; a whole object's for a portal copy,
    /// through the contact batch's modification hook). `keep[i]` is 1
    /// where the lane's manifold has point `i`, else 0; `a`, `b` are the
    /// bodies' velocities. Resets the impulses without warm starting and
    /// the step totals.
    #[inline(always)]
    pub(crate) fn prepare(
        &mut self,
        ctx: &StepContext,
        k_masses: [L; 4],
        keep: [L; MAX_MANIFOLD_POINTS],
        a: &Velocity<L>,
        b: &Velocity<L>,
    ) {
        let zero = L::splat(0.0);
        let one = L::splat(1.0);
        let [inv_mass_a, inv_inertia_a, inv_mass_b, inv_inertia_b] = k_masses;
        // A pair with a static (or kinematic, or sleeping) body, by the
        // masses the impulses act with.
        let static_pair = self.inv_mass_a.eq(zero) | self.inv_mass_b.eq(zero);
        let (contact, fixed) = (ctx.contact_softness, ctx.static_softness);
        self.bias_rate = L::select(
            static_pair,
            L::splat(fixed.bias_rate),
            L::splat(contact.bias_rate),
        );
        let rho_max = ctx.contact_mass_ratio_cap;
        let stiffen = rho_max > 1.0 && contact.impulse_scale > 0.0;
        // a₂ = s_m / s_i of the contact softness (Softness::with_mass_ratio).
        let a2 = if contact.impulse_scale > 0.0 {
            contact.mass_scale / contact.impulse_scale
        } else {
            0.0
        };
        let (n_x, n_y) = (self.n_x, self.n_y);
        let c_dot_linear = (b.v_x - a.v_x) * n_x + (b.v_y - a.v_y) * n_y;
        for i in 0..MAX_MANIFOLD_POINTS {
            let (rn_a, rn_b) = (self.ja[i], self.jb[i]);
            let (rt_a, rt_b) = (self.ja[i + 2], self.jb[i + 2]);
            let k_a = inv_mass_a + inv_inertia_a * rn_a * rn_a;
            let k_b = inv_mass_b + inv_inertia_b * rn_b * rn_b;
            let k = k_a + k_b;
            let normal_mass = L::select(k.gt(zero), one / k, zero) * keep[i];
            // Softness::with_mass_ratio: ρ = min(k / min(k_a, k_b), ρ_max).
            // Only the impulse scale is kept: the mass scale is 1 − s_i.
            let mut impulse_scale = L::splat(contact.impulse_scale);
            if stiffen {
                let k_heavy = k_a.at_most(k_b);
                let rho = (k / k_heavy).at_most(L::splat(rho_max));
                let stiffer = k_heavy.gt(zero) & rho.gt(one);
                let scaled = one / (one + rho * L::splat(a2));
                impulse_scale = L::select(stiffer, scaled, impulse_scale);
            }
            self.impulse_scale[i] =
                L::select(static_pair, L::splat(fixed.impulse_scale), impulse_scale);
            self.mass[i] = normal_mass;
            let k_t =
                inv_mass_a + inv_mass_b + inv_inertia_a * rt_a * rt_a + inv_inertia_b * rt_b * rt_b;
            self.mass[i + 2] = L::select(k_t.gt(zero), one / k_t, zero) * keep[i];
            self.relative_velocity[i] = c_dot_linear + (b.w * rn_b - a.w * rn_a);
            self.max_normal_impulse[i] = zero;
        }
        // The block of the two normal rows: K = [[k00, k01], [k01, k11]].
        let (ja, jb) = (self.ja, self.jb);
        let m_ab = inv_mass_a + inv_mass_b;
        let (i_a, i_b) = (inv_inertia_a, inv_inertia_b);
        let k00 = m_ab + i_a * ja[0] * ja[0] + i_b * jb[0] * jb[0];
        let k11 = m_ab + i_a * ja[1] * ja[1] + i_b * jb[1] * jb[1];
        let k01 = m_ab + i_a * ja[0] * ja[1] + i_b * jb[0] * jb[1];
        let det = k00 * k11 - k01 * k01;
        let well_conditioned = (k00 * k00).lt(L::splat(BLOCK_CONDITION) * det) & det.gt(zero);
        self.block = well_conditioned & keep[1].gt(zero);
        self.block_k = [k00, k11];
        if !ctx.warm_starting {
            self.impulse = [zero; ROWS];
        }
        self.step_base = self.impulse.map(|l| -l);
        if let Some(s) = self.surface.as_deref_mut() {
            // The rolling row: J = [0 −1 0 1], k = i_a⁻¹ + i_b⁻¹.
            let k = inv_inertia_a + inv_inertia_b;
            s.rolling_mass = L::select(k.gt(zero), one / k, zero);
            s.rolling_impulse = zero;
        }
    }

    /// The warm start: adds the kept impulses to the step totals and
    /// returns them as one push, `Δv = M⁻¹ Jᵀ λ`, for
    /// [`ContactRows::push_a`] and [`ContactRows::push_b`] (one side at a
    /// time: the wide lanes then hold one side's velocities at once).
    #[inline(always)]
    pub(crate) fn warm_start(&mut self) -> Push<L> {
        let (n_x, n_y) = (self.n_x, self.n_y);
        let lambda = &self.impulse;
        for (base, &l) in self.step_base.iter_mut().zip(lambda) {
            *base += l;
        }
        let (pn, pt) = (lambda[0] + lambda[1], lambda[2] + lambda[3]);
        // p = pn n + pt t with t = (n_y, −n_x).
        let mut push = Push {
            p_x: pn * n_x + pt * n_y,
            p_y: pn * n_y - pt * n_x,
            l_a: dot_rows(lambda, &self.ja),
            l_b: dot_rows(lambda, &self.jb),
        };
        if let Some(s) = self.surface.as_deref() {
            // The rolling row turns both bodies, J = [0 −1 0 1].
            push.l_a += s.rolling_impulse;
            push.l_b += s.rolling_impulse;
        }
        push
    }

    /// Body a's share of a push: `v_a −= m_a⁻¹ p`, `ω_a −= i_a⁻¹ l_a`.
    #[inline(always)]
    pub(crate) fn push_a(&self, push: &Push<L>, a: &mut Velocity<L>) {
        a.v_x -= self.inv_mass_a * push.p_x;
        a.v_y -= self.inv_mass_a * push.p_y;
        a.w -= self.inv_inertia_a * push.l_a;
    }

    /// Body b's share of a push: `v_b += m_b⁻¹ p`, `ω_b += i_b⁻¹ l_b`.
    #[inline(always)]
    pub(crate) fn push_b(&self, push: &Push<L>, b: &mut Velocity<L>) {
        b.v_x += self.inv_mass_b * push.p_x;
        b.v_y += self.inv_mass_b * push.p_y;
        b.w += self.inv_inertia_b * push.l_b;
    }

    /// One velocity iteration (module docs, Evaluation): `Ċ` of every row
    /// from the velocities `a`, `b`; the normal rows as a block where it
    /// holds, else one by one; the friction rows; then the velocities,
    /// once. `USE_BIAS`: the soft push-out (else relax). `da`, `db` are
    /// the bodies' position deltas.
    ///
    /// `BOTH_ORDERS`: the normal rows solved one by one are taken in both
    /// orders and averaged (`Δλ = (Δλ_01 + Δλ_10) / 2`), for contacts that
    /// may not use the block (a portal copy's, built on its object's
    /// masses), so that a manifold met evenly (a flat face) is pushed
    /// evenly. In one order the first point takes the larger share: a box
    /// whose copy hit a ceiling flat at 8 m/s came away turning and rocked
    /// on one corner for seconds.
    #[inline(always)]
    pub(crate) fn solve<const USE_BIAS: bool, const BOTH_ORDERS: bool>(
        &mut self,
        a: &mut Velocity<L>,
        da: &Delta<L>,
        b: &mut Velocity<L>,
        db: &Delta<L>,
        inv_h: L,
        push_max: L,
    ) {
        if self.surface.is_some() {
            self.solve_rows::<USE_BIAS, true, BOTH_ORDERS>(a, da, b, db, inv_h, push_max);
        } else {
            self.solve_rows::<USE_BIAS, false, BOTH_ORDERS>(a, da, b, db, inv_h, push_max);
        }
    }

    /// [`ContactRows::solve`] with (`SURFACE`) or without surface rows.
    #[inline(always)]
    fn solve_rows<const USE_BIAS: bool, const SURFACE: bool, const BOTH_ORDERS: bool>(
        &mut self,
        a: &mut Velocity<L>,
        da: &Delta<L>,
        b: &mut Velocity<L>,
        db: &Delta<L>,
        inv_h: L,
        push_max: L,
    ) {
        let zero = L::splat(0.0);
        let (n_x, n_y) = (self.n_x, self.n_y);
        let (ja, jb) = (self.ja, self.jb);
        let dpn = (db.dp_x - da.dp_x) * n_x + (db.dp_y - da.dp_y) * n_y;

        // Ċ of every row at the loaded velocities (t = (n_y, −n_x)).
        let dv_x = b.v_x - a.v_x;
        let dv_y = b.v_y - a.v_y;
        let dvn = dv_x * n_x + dv_y * n_y;
        let dvt = dv_x * n_y - dv_y * n_x;
        let c_dot0 = dvn + (b.w * jb[0] - a.w * ja[0]);
        let c_dot1 = dvn + (b.w * jb[1] - a.w * ja[1]);
        let c_dot2 = dvt + (b.w * jb[2] - a.w * ja[2]);
        let c_dot3 = dvt + (b.w * jb[3] - a.w * ja[3]);

        // K_ij = J_j M⁻¹ J_iᵀ for i < j (n · t = 0).
        let (i_a, i_b) = (self.inv_inertia_a, self.inv_inertia_b);
        let m_ab = self.inv_mass_a + self.inv_mass_b;
        let (ka0, ka1, ka2) = (i_a * ja[0], i_a * ja[1], i_a * ja[2]);
        let (kb0, kb1, kb2) = (i_b * jb[0], i_b * jb[1], i_b * jb[2]);
        let k01 = m_ab + (ka0 * ja[1] + kb0 * jb[1]);
        let k02 = ka0 * ja[2] + kb0 * jb[2];
        let k03 = ka0 * ja[3] + kb0 * jb[3];
        let k12 = ka1 * ja[2] + kb1 * jb[2];
        let k13 = ka1 * ja[3] + kb1 * jb[3];
        let k23 = m_ab + (ka2 * ja[3] + kb2 * jb[3]);

        let (b0, ms0, is0) = self.normal_terms::<USE_BIAS>(0, dpn, da, db, inv_h, push_max);
        let (b1, ms1, is1) = self.normal_terms::<USE_BIAS>(1, dpn, da, db, inv_h, push_max);
        let (old0, old1) = (self.impulse[0], self.impulse[1]);
        // Gauss–Seidel: point 0, then point 1, each clamped to λ + Δλ ≥ 0.
        let g0 = soft_impulse(self.mass[0] * ms0, c_dot0 + b0, is0, old0).at_least(-old0);
        let c_dot1_after = c_dot1 + k01 * g0;
        let g1 = soft_impulse(self.mass[1] * ms1, c_dot1_after + b1, is1, old1).at_least(-old1);
        let (g0, g1) = if BOTH_ORDERS {
            // Point 1, then point 0; the two orders averaged (each step
            // keeps λ + Δλ ≥ 0, so their mean does).
            let h1 = soft_impulse(self.mass[1] * ms1, c_dot1 + b1, is1, old1).at_least(-old1);
            let c_dot0_after = c_dot0 + k01 * h1;
            let h0 = soft_impulse(self.mass[0] * ms0, c_dot0_after + b0, is0, old0).at_least(-old0);
            let half = L::splat(0.5);
            ((g0 + h0) * half, (g1 + h1) * half)
        } else {
            (g0, g1)
        };
        // Both points at once, each its own soft spring:
        // K' λ' = K λ − (Ċ + b), K' = K + diag(k_ii (1/s_m − 1)).
        let [k00, k11] = self.block_k;
        let q0 = (c_dot0 + b0) - (k00 * old0 + k01 * old1);
        let q1 = (c_dot1 + b1) - (k01 * old0 + k11 * old1);
        let (kp00, kp11) = (k00 / ms0, k11 / ms1);
        let inv_det = L::splat(1.0) / (kp00 * kp11 - k01 * k01);
        let x0 = (k01 * q1 - kp11 * q0) * inv_det - old0;
        let x1 = (k01 * q0 - kp00 * q1) * inv_det - old1;
        let block = self.block & (old0 + x0).ge(zero) & (old1 + x1).ge(zero);
        let d0 = L::select(block, x0, g0);
        let d1 = L::select(block, x1, g1);
        self.impulse[0] = old0 + d0;
        self.impulse[1] = old1 + d1;
        self.max_normal_impulse[0] = d0.at_least(self.max_normal_impulse[0]);
        self.max_normal_impulse[1] = d1.at_least(self.max_normal_impulse[1]);

        // Friction rows (towards the surface's tangent speed, if any).
        let mut c_dot2 = (c_dot2 + k02 * d0) + k12 * d1;
        if SURFACE {
            c_dot2 = self.friction_target(c_dot2);
        }
        let d2 = self.friction_row(2, c_dot2);
        let mut c_dot3 = ((c_dot3 + k03 * d0) + k13 * d1) + k23 * d2;
        if SURFACE {
            c_dot3 = self.friction_target(c_dot3);
        }
        let d3 = self.friction_row(3, c_dot3);

        // The velocities, once: Δv = M⁻¹ Jᵀ Δλ summed over the rows.
        let d = [d0, d1, d2, d3];
        let (pn, pt) = (d0 + d1, d2 + d3);
        let p_x = pn * n_x + pt * n_y;
        let p_y = pn * n_y - pt * n_x;
        let mut l_a = dot_rows(&d, &ja);
        let mut l_b = dot_rows(&d, &jb);
        if SURFACE {
            // The rolling row last: its Ċ = ω_b − ω_a advanced by the
            // rows above, K_ir = i_a⁻¹ (r_a × ·)_i + i_b⁻¹ (r_b × ·)_i.
            let (ka3, kb3) = (i_a * ja[3], i_b * jb[3]);
            let c_dot_r = (b.w - a.w)
                + (((ka0 + kb0) * d0 + (ka1 + kb1) * d1) + ((ka2 + kb2) * d2 + (ka3 + kb3) * d3));
            let d_r = self.rolling_row(c_dot_r);
            l_a += d_r;
            l_b += d_r;
        }
        a.v_x -= self.inv_mass_a * p_x;
        a.v_y -= self.inv_mass_a * p_y;
        a.w -= i_a * l_a;
        b.v_x += self.inv_mass_b * p_x;
        b.v_y += self.inv_mass_b * p_y;
        b.w += i_b * l_b;
    }

    /// The terms of point `i`'s normal row: the bias `b` (m/s), the mass
    /// scale `s_m` and the impulse scale `s_i` of
    /// `Δλ = −s_m k⁻¹ (Ċ + b) − s_i λ`: speculative (`s > 0`) rigid with
    /// `b = s / h`, soft push-out with `b = max(β s, −v_push)`, relax rigid
    /// with `b = max(s / h, 0)`. `dpn = n · (dp_b − dp_a)`.
    #[inline(always)]
    pub(crate) fn normal_terms<const USE_BIAS: bool>(
        &self,
        i: usize,
        dpn: L,
        da: &Delta<L>,
        db: &Delta<L>,
        inv_h: L,
        push_max: L,
    ) -> (L, L, L) {
        let (ja, jb) = (&self.ja, &self.jb);
        // The current separation, anchors fixed on the bodies:
        // n · (dq r) = (r × n) sin − (r × t) cos.
        let s = self.base_separation[i]
            + dpn
            + (db.q_s * jb[i] - db.q_c * jb[i + 2])
            + (da.q_c * ja[i + 2] - da.q_s * ja[i]);
        let zero = L::splat(0.0);
        let one = L::splat(1.0);
        if USE_BIAS {
            let speculative = s.gt(zero);
            let soft_bias = (self.bias_rate * s).at_least(-push_max);
            let impulse_scale = self.impulse_scale[i];
            (
                L::select(speculative, s * inv_h, soft_bias),
                // s_m + s_i = 1 (Softness).
                L::select(speculative, one, one - impulse_scale),
                L::select(speculative, zero, impulse_scale),
            )
        } else {
            ((s * inv_h).at_least(zero), one, zero)
        }
    }

    /// Friction row `i` (2 or 3) given its `Ċ`: accumulates the impulse,
    /// bounded by `±μ λ_n` of its point, and returns the increment.
    #[inline(always)]
    pub(crate) fn friction_row(&mut self, i: usize, c_dot: L) -> L {
        let old = self.impulse[i];
        let max_friction = self.friction * self.impulse[i - MAX_MANIFOLD_POINTS];
        let min_friction = -max_friction;
        let d = (-(self.mass[i] * c_dot)).clamp_to(min_friction - old, max_friction - old);
        self.impulse[i] = (old + d).clamp_to(min_friction, max_friction);
        d
    }

    /// A friction row's `Ċ` measured against the surface's tangent speed:
    /// `Ċ − v_t` (the row then drives the relative tangent speed to `v_t`);
    /// `Ċ` itself without surface rows.
    #[inline(always)]
    pub(crate) fn friction_target(&self, c_dot: L) -> L {
        match self.surface.as_deref() {
            Some(s) => c_dot - s.tangent_speed,
            None => c_dot,
        }
    }

    /// The rolling row given its `Ċ = ω_b − ω_a`: accumulates the impulse,
    /// bounded by `±c r (λ_n0 + λ_n1)` (the rolling resistance times the
    /// rolling radius times the contact's normal impulse), and returns the
    /// increment (0 without surface rows).
    #[inline(always)]
    pub(crate) fn rolling_row(&mut self, c_dot: L) -> L {
        let total_normal = self.impulse[0] + self.impulse[1];
        let Some(s) = self.surface.as_deref_mut() else {
            return L::splat(0.0);
        };
        let old = s.rolling_impulse;
        let max = s.rolling_resistance * total_normal;
        let new = (old - s.rolling_mass * c_dot).clamp_to(-max, max);
        s.rolling_impulse = new;
        new - old
    }

    /// Whether some lane has restitution.
    #[inline(always)]
    pub(crate) fn has_restitution(&self) -> bool {
        L::any(self.restitution.gt(L::splat(0.0)))
    }

    /// Restitution, point 0 then point 1: where a point approached faster
    /// than `threshold` (m/s) before the solve and pushed, drive `Ċ` to
    /// `−e · Ċ_before`.
    #[inline(always)]
    pub(crate) fn restitution(&mut self, a: &mut Velocity<L>, b: &mut Velocity<L>, threshold: L) {
        let zero = L::splat(0.0);
        let (n_x, n_y) = (self.n_x, self.n_y);
        let e = self.restitution;
        for i in 0..MAX_MANIFOLD_POINTS {
            let rv = self.relative_velocity[i];
            let active = e.gt(zero) & rv.lt(-threshold) & self.max_normal_impulse[i].ne(zero);
            if !L::any(active) {
                continue;
            }
            let (rn_a, rn_b) = (self.ja[i], self.jb[i]);
            let c_dot = (b.v_x - a.v_x) * n_x + (b.v_y - a.v_y) * n_y + (b.w * rn_b - a.w * rn_a);
            let lambda = -(self.mass[i] * (c_dot + e * rv));
            let old = self.impulse[i];
            let new_impulse = (old + lambda).at_least(zero);
            let applied = L::select(active, new_impulse - old, zero);
            self.impulse[i] = old + applied;
            self.max_normal_impulse[i] = self.max_normal_impulse[i].at_least(applied);
            let (p_x, p_y) = (applied * n_x, applied * n_y);
            a.v_x -= self.inv_mass_a * p_x;
            a.v_y -= self.inv_mass_a * p_y;
            a.w -= self.inv_inertia_a * applied * rn_a;
            b.v_x += self.inv_mass_b * p_x;
            b.v_y += self.inv_mass_b * p_y;
            b.w += self.inv_inertia_b * applied * rn_b;
        }
    }
}

/// The softness of one normal row as `rows()` reports it: the contact
/// softness scaled by the mass ratio `ρ = min(k / min(k_a, k_b), ρ_max)` of
/// the point's two effective masses (1 for a pair with a static body);
/// its impulse scale is the one [`ContactRows::prepare`] computes.
pub(crate) fn normal_softness(
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
