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
//!   contact [`Softness`](janus2d_core::softness::Softness) (twice the hertz
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
//! **Friction row.** `J` as above with `t` for `n`, no position error;
//! the accumulated impulse is clamped to `±μ λ_n` (Coulomb), with
//! `μ = √(μ_a μ_b)`.
//!
//! **Restitution.** Once after the substeps, for points that approached
//! faster than the threshold: drive `Ċ` to `−e · Ċ_before`, `e = max(e_a, e_b)`.

use janus2d_core::body::{BodyHandle, BodySet, BodyState};
use janus2d_core::constraint::{Block, BodyJacobian, Constraint, ConstraintRows, Row, StepContext};
use janus2d_core::math::{Real, Vec2, cross};
use janus2d_core::softness::Softness;
use smallvec::smallvec;

use crate::parts::{AxisPart, load_pair, store_pair};

/// Maximum points per manifold.
pub const MAX_MANIFOLD_POINTS: usize = 2;

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

/// One solver point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct ContactPoint {
    r_a: Vec2,
    r_b: Vec2,
    base_separation: Real,
    normal: AxisPart,
    tangent: AxisPart,
    /// Largest normal impulse applied in one iteration (restitution gate).
    max_normal_impulse: Real,
    /// Normal velocity before the solve (for restitution), m/s.
    relative_velocity: Real,
    /// Soft mass scale `s_m` of this point's normal row (dimensionless).
    mass_scale: Real,
    /// Soft impulse scale `s_i` of this point's normal row (dimensionless).
    impulse_scale: Real,
    /// Angular Jacobian parts `r_a × n`, `r_b × n`, `r_a × t`, `r_b × t`
    /// (the anchors are fixed for the step), m.
    rn_a: Real,
    rn_b: Real,
    rt_a: Real,
    rt_b: Real,
}

/// A contact constraint between two bodies (one manifold, 1–2 points).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactConstraint {
    /// Body a.
    pub body_a: BodyHandle,
    /// Body b.
    pub body_b: BodyHandle,
    /// Unit normal from a to b (world).
    pub normal: Vec2,
    /// Mixed friction coefficient `√(μ_a μ_b)`.
    pub friction: Real,
    /// Mixed restitution `max(e_a, e_b)`.
    pub restitution: Real,
    /// Index of the contact in the world's contact list (for storing impulses).
    pub contact_index: u32,
    state_a: u32,
    state_b: u32,
    point_count: usize,
    points: [ContactPoint; MAX_MANIFOLD_POINTS],
    softness: Softness,
    /// Inverse mass and inertia of the whole object a body belongs to, when
    /// it is one copy of an object crossing a portal (see
    /// [`ContactConstraint::set_object_mass`]).
    object_mass: [Option<(Real, Real)>; 2],
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
        let mut c = ContactConstraint {
            body_a,
            body_b,
            normal,
            friction,
            restitution,
            contact_index,
            state_a: 0,
            state_b: 0,
            point_count: points.len().min(MAX_MANIFOLD_POINTS),
            points: [ContactPoint::default(); MAX_MANIFOLD_POINTS],
            softness: Softness::RIGID,
            object_mass: [None, None],
        };
        for (cp, input) in c.points.iter_mut().zip(points) {
            cp.r_a = input.anchor_a;
            cp.r_b = input.anchor_b;
            cp.base_separation = input.separation - (input.anchor_b - input.anchor_a).dot(normal);
            cp.normal.impulse = input.normal_impulse;
            cp.tangent.impulse = input.tangent_impulse;
        }
        c
    }

    /// Makes body `side` (0: a, 1: b) respond as the whole object it is a
    /// copy of: while an object crosses a portal its two copies move as one,
    /// so a contact on one copy must stop the object, not only the copy.
    /// The effective masses use the object's inverse mass and inertia; the
    /// impulses still act on the copy, and the portal constraint carries
    /// the object's share to the other copy.
    pub fn set_object_mass(&mut self, side: usize, inv_mass: Real, inv_inertia: Real) {
        self.object_mass[side] = Some((inv_mass, inv_inertia));
    }

    /// Number of points.
    pub fn point_count(&self) -> usize {
        self.point_count
    }

    /// Accumulated (normal, tangent) impulses of point `i`, N·s.
    pub fn impulses(&self, i: usize) -> (Real, Real) {
        (
            self.points[i].normal.impulse,
            self.points[i].tangent.impulse,
        )
    }

    /// Total normal impulse of the last step, N·s.
    pub fn total_normal_impulse(&self) -> Real {
        self.points[..self.point_count]
            .iter()
            .map(|p| p.normal.impulse)
            .sum()
    }

    #[inline(always)]
    fn tangent(&self) -> Vec2 {
        Vec2::new(self.normal.y, -self.normal.x)
    }
}

impl Constraint for ContactConstraint {
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        let a = bodies.solver_body(self.body_a);
        let b = bodies.solver_body(self.body_b);
        self.state_a = a.state_index;
        self.state_b = b.state_index;
        let (mut sa, mut sb) = (*a.state, *b.state);
        let static_pair = sa.inv_mass == 0.0 || sb.inv_mass == 0.0;
        // Crossing copies respond as their whole object (K only).
        if let Some((m, i)) = self.object_mass[0] {
            (sa.inv_mass, sa.inv_inertia) = (m, i);
        }
        if let Some((m, i)) = self.object_mass[1] {
            (sb.inv_mass, sb.inv_inertia) = (m, i);
        }
        let (sa, sb) = (&sa, &sb);
        self.softness = if static_pair {
            ctx.static_softness
        } else {
            ctx.contact_softness
        };
        let moving_pair = !static_pair;
        let rho_max = ctx.contact_mass_ratio_cap;
        let n = self.normal;
        let t = self.tangent();
        for cp in &mut self.points[..self.point_count] {
            let rn_a = cross(cp.r_a, n);
            let rn_b = cross(cp.r_b, n);
            let k_a = sa.inv_mass + sa.inv_inertia * rn_a * rn_a;
            let k_b = sb.inv_mass + sb.inv_inertia * rn_b * rn_b;
            let k = k_a + k_b;
            let k_heavy = k_a.min(k_b);
            let rho = if moving_pair && rho_max > 1.0 && k_heavy > 0.0 {
                (k / k_heavy).min(rho_max)
            } else {
                1.0
            };
            let soft = self.softness.with_mass_ratio(rho);
            cp.mass_scale = soft.mass_scale;
            cp.impulse_scale = soft.impulse_scale;
            cp.rn_a = rn_a;
            cp.rn_b = rn_b;
            cp.rt_a = cross(cp.r_a, t);
            cp.rt_b = cross(cp.r_b, t);
            cp.normal.set_mass(k);
            cp.tangent.set_mass(AxisPart::k(sa, sb, cp.r_a, cp.r_b, t));
            cp.relative_velocity = AxisPart::c_dot(sa, sb, cp.r_a, cp.r_b, n);
            cp.max_normal_impulse = 0.0;
            if !ctx.warm_starting {
                cp.normal.impulse = 0.0;
                cp.tangent.impulse = 0.0;
            }
        }
    }

    fn warm_start(&mut self, _ctx: &StepContext, states: &mut [BodyState]) {
        let (mut sa, mut sb) = load_pair(states, self.state_a, self.state_b);
        let (n, t) = (self.normal, self.tangent());
        let (m_a, i_a, m_b, i_b) = (sa.inv_mass, sa.inv_inertia, sb.inv_mass, sb.inv_inertia);
        for cp in &self.points[..self.point_count] {
            let (lambda_n, lambda_t) = (cp.normal.impulse, cp.tangent.impulse);
            let p = lambda_n * n + lambda_t * t;
            sa.v -= m_a * p;
            sa.w -= i_a * (lambda_n * cp.rn_a + lambda_t * cp.rt_a);
            sb.v += m_b * p;
            sb.w += i_b * (lambda_n * cp.rn_b + lambda_t * cp.rt_b);
        }
        store_pair(states, self.state_a, self.state_b, &sa, &sb);
    }

    fn solve(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        let (sa, sb) = load_pair(states, self.state_a, self.state_b);
        let (m_a, i_a, m_b, i_b) = (sa.inv_mass, sa.inv_inertia, sb.inv_mass, sb.inv_inertia);
        let (mut v_a, mut w_a, mut v_b, mut w_b) = (sa.v, sa.w, sb.v, sb.w);
        let n = self.normal;
        let dp = sb.dp - sa.dp;
        let bias_rate = self.softness.bias_rate;
        let push_max = ctx.contact_push_max_velocity;
        let inv_h = ctx.inv_h;
        let count = self.point_count;
        for cp in &mut self.points[..count] {
            // Current separation from the deltas, anchors fixed on the bodies.
            let ds = dp + sb.dq.rotate(cp.r_b) - sa.dq.rotate(cp.r_a);
            let s = cp.base_separation + ds.dot(n);
            let (bias, mass_scale, impulse_scale) = if s > 0.0 {
                (s * inv_h, 1.0, 0.0)
            } else if use_bias {
                (
                    (bias_rate * s).max(-push_max),
                    cp.mass_scale,
                    cp.impulse_scale,
                )
            } else {
                (0.0, 1.0, 0.0)
            };
            // Ċ = n · (v_b − v_a) + ω_b (r_b × n) − ω_a (r_a × n).
            let c_dot = (v_b - v_a).dot(n) + w_b * cp.rn_b - w_a * cp.rn_a;
            let old = cp.normal.impulse;
            let lambda = -cp.normal.mass * mass_scale * (c_dot + bias) - impulse_scale * old;
            let new_impulse = (old + lambda).max(0.0);
            let applied = new_impulse - old;
            cp.normal.impulse = new_impulse;
            cp.max_normal_impulse = cp.max_normal_impulse.max(applied);
            let p = applied * n;
            v_a -= m_a * p;
            w_a -= i_a * applied * cp.rn_a;
            v_b += m_b * p;
            w_b += i_b * applied * cp.rn_b;
        }
        let t = self.tangent();
        let friction = self.friction;
        for cp in &mut self.points[..count] {
            let c_dot = (v_b - v_a).dot(t) + w_b * cp.rt_b - w_a * cp.rt_a;
            let old = cp.tangent.impulse;
            let max_friction = friction * cp.normal.impulse;
            let new_impulse = (old - cp.tangent.mass * c_dot).clamp(-max_friction, max_friction);
            let applied = new_impulse - old;
            cp.tangent.impulse = new_impulse;
            let p = applied * t;
            v_a -= m_a * p;
            w_a -= i_a * applied * cp.rt_a;
            v_b += m_b * p;
            w_b += i_b * applied * cp.rt_b;
        }
        let ta = &mut states[self.state_a as usize];
        ta.v = v_a;
        ta.w = w_a;
        let tb = &mut states[self.state_b as usize];
        tb.v = v_b;
        tb.w = w_b;
    }

    fn apply_restitution(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        if self.restitution == 0.0 {
            return;
        }
        let (mut sa, mut sb) = load_pair(states, self.state_a, self.state_b);
        let n = self.normal;
        let e = self.restitution;
        for cp in &mut self.points[..self.point_count] {
            if cp.relative_velocity > -ctx.restitution_threshold || cp.max_normal_impulse == 0.0 {
                continue;
            }
            let c_dot = AxisPart::c_dot(&sa, &sb, cp.r_a, cp.r_b, n);
            let lambda = -cp.normal.mass * (c_dot + e * cp.relative_velocity);
            let new_impulse = (cp.normal.impulse + lambda).max(0.0);
            let applied = new_impulse - cp.normal.impulse;
            cp.normal.impulse = new_impulse;
            cp.max_normal_impulse = cp.max_normal_impulse.max(applied);
            AxisPart::apply(&mut sa, &mut sb, cp.r_a, cp.r_b, n, applied);
        }
        store_pair(states, self.state_a, self.state_b, &sa, &sb);
    }

    fn rows(&self, ctx: &StepContext, bodies: &BodySet) -> ConstraintRows {
        let a = bodies.solver_body(self.body_a);
        let b = bodies.solver_body(self.body_b);
        let (sa, sb) = (a.state, b.state);
        let static_pair = sa.inv_mass == 0.0 || sb.inv_mass == 0.0;
        let softness = if static_pair {
            ctx.static_softness
        } else {
            ctx.contact_softness
        };
        let mut out = ConstraintRows::default();
        let entry = |body, linear: Vec2, angular, s: &BodyState| BodyJacobian {
            body,
            linear,
            angular,
            inv_mass: s.inv_mass,
            inv_inertia: s.inv_inertia,
        };
        for (axis, is_normal) in [(self.normal, true), (self.tangent(), false)] {
            for cp in &self.points[..self.point_count] {
                let first_row = out.rows.len();
                let (c, softness, lower, upper, impulse) = if is_normal {
                    let s = cp.base_separation + (cp.r_b - cp.r_a).dot(self.normal);
                    (s, softness, 0.0, Real::INFINITY, cp.normal.impulse)
                } else {
                    let m = self.friction * cp.normal.impulse;
                    (0.0, Softness::RIGID, -m, m, cp.tangent.impulse)
                };
                out.rows.push(Row {
                    jacobian: smallvec![
                        entry(self.body_a, -axis, -cross(cp.r_a, axis), sa),
                        entry(self.body_b, axis, cross(cp.r_b, axis), sb),
                    ],
                    c,
                    softness,
                    lower,
                    upper,
                    impulse,
                });
                let k = AxisPart::k(sa, sb, cp.r_a, cp.r_b, axis);
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
