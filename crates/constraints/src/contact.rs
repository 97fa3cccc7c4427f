//! The contact constraint of the scalar overflow: one manifold (1–2
//! points) between two bodies, with Coulomb friction and restitution.
//!
//! [`ContactConstraint`] holds one contact's rows (`ContactRows` on
//! `Real`) and its identity (bodies, state indices, contact index); its
//! stages load the two bodies' states, run the row code of
//! [`crate::contact_row`] (where the rows are derived), and store the
//! velocities back. The colours' SIMD chunks run the same row code on
//! [`LANES`](crate::lane::LANES) contacts at a time
//! ([`crate::contact_solver`]).

use janus2d_core::body::{BodyHandle, BodySet, BodyState, InvMass};
use janus2d_core::constraint::{Block, BodyJacobian, Constraint, ConstraintRows, Row, StepContext};
use janus2d_core::math::{Real, Vec2};
use janus2d_core::softness::Softness;
use smallvec::smallvec;

use crate::contact_row::{ContactRows, Delta, Velocity, normal_softness};

pub use crate::contact_row::{ContactPointInput, MAX_MANIFOLD_POINTS};

/// A contact constraint between two bodies (one manifold, 1–2 points).
///
/// The rows are stored by row (normal 0, normal 1, friction 0, friction 1)
/// in `ContactRows`, what the warm start reads first; the anchors
/// themselves are not kept: the Jacobian's angular parts determine them,
/// `r = (r × n) t − (r × t) n`.
#[derive(Clone, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct ContactConstraint {
    /// The rows (`L = Real`).
    pub(crate) rows: ContactRows<Real>,
    /// State index of body a (0: static, sleeping or stale).
    pub(crate) state_a: u32,
    /// State index of body b.
    pub(crate) state_b: u32,
    /// Number of points (0 to 2).
    pub(crate) point_count: u32,
    /// Index of the contact in the world's contact list (for storing impulses).
    pub contact_index: u32,
    /// Body a.
    pub body_a: BodyHandle,
    /// Body b.
    pub body_b: BodyHandle,
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
        let mut rows = ContactRows::empty();
        // The inverse masses are loaded from the bodies at prepare.
        rows.set_lane(0, normal, points, friction, restitution, [0.0; 4]);
        ContactConstraint {
            rows,
            state_a: 0,
            state_b: 0,
            point_count: points.len().min(MAX_MANIFOLD_POINTS) as u32,
            contact_index,
            body_a,
            body_b,
        }
    }

    /// Unit normal from a to b (world).
    #[must_use]
    pub fn normal(&self) -> Vec2 {
        Vec2::new(self.rows.n_x, self.rows.n_y)
    }

    /// Mixed friction coefficient `√(μ_a μ_b)`.
    #[must_use]
    pub fn friction(&self) -> Real {
        self.rows.friction
    }

    /// Mixed restitution `max(e_a, e_b)`.
    #[must_use]
    pub fn restitution(&self) -> Real {
        self.rows.restitution
    }

    /// The inverse masses and inertias the impulses act with, loaded from
    /// the bodies at prepare: `[m_a⁻¹, i_a⁻¹, m_b⁻¹, i_b⁻¹]`.
    #[inline(always)]
    pub(crate) fn applied_masses(&self) -> [Real; 4] {
        let r = &self.rows;
        [r.inv_mass_a, r.inv_inertia_a, r.inv_mass_b, r.inv_inertia_b]
    }

    /// `[1, 1]` for two points, `[1, 0]` for one.
    #[inline(always)]
    fn keep(&self) -> [Real; MAX_MANIFOLD_POINTS] {
        [1.0, if self.point_count == 2 { 1.0 } else { 0.0 }]
    }

    /// The effective masses and softness of every row from the inverse
    /// masses `k_masses = [m_a⁻¹, i_a⁻¹, m_b⁻¹, i_b⁻¹]` (the bodies' own
    /// at prepare; a whole object's for a portal copy, through the contact
    /// batch's modification hook): [`ContactRows::prepare`].
    pub(crate) fn prepare_rows(
        &mut self,
        ctx: &StepContext,
        bodies: &BodySet,
        k_masses: [Real; 4],
    ) {
        let a = Velocity::of(&bodies.states[self.state_a as usize]);
        let b = Velocity::of(&bodies.states[self.state_b as usize]);
        let keep = self.keep();
        self.rows.prepare(ctx, k_masses, keep, &a, &b);
    }

    /// Applies the impulses kept from the last step, `Δv = M⁻¹ Jᵀ λ`.
    pub(crate) fn apply_warm_start(&mut self, states: &mut [BodyState]) {
        let (ia, ib) = (self.state_a as usize, self.state_b as usize);
        let push = self.rows.warm_start();
        let mut a = Velocity::of(&states[ia]);
        self.rows.push_a(&push, &mut a);
        a.store(&mut states[ia]);
        let mut b = Velocity::of(&states[ib]);
        self.rows.push_b(&push, &mut b);
        b.store(&mut states[ib]);
    }

    /// Number of points.
    pub fn point_count(&self) -> usize {
        self.point_count as usize
    }

    /// Accumulated (normal, tangent) impulses of point `i`, N·s.
    pub fn impulses(&self, i: usize) -> (Real, Real) {
        let impulse = &self.rows.impulse;
        (impulse[i], impulse[i + MAX_MANIFOLD_POINTS])
    }

    /// The kept and step-total impulses of point `i`.
    #[must_use]
    pub fn point_impulse(&self, i: usize) -> crate::contact_row::PointImpulse {
        let (n, t) = self.impulses(i);
        let base = &self.rows.step_base;
        crate::contact_row::PointImpulse {
            normal: n,
            tangent: t,
            total_normal: base[i] + n,
            total_tangent: base[i + MAX_MANIFOLD_POINTS] + t,
        }
    }

    #[inline(always)]
    fn tangent(&self) -> Vec2 {
        Vec2::new(self.rows.n_y, -self.rows.n_x)
    }

    /// One velocity iteration ([`ContactRows::solve`]): the normal rows
    /// (as a block or one by one), then the friction rows.
    /// `BOTH_ORDERS`: the normal rows solved one by one are taken in both
    /// orders and averaged (see [`ContactRows::solve`]).
    #[inline(always)]
    pub(crate) fn solve_rows<const USE_BIAS: bool, const BOTH_ORDERS: bool>(
        &mut self,
        states: &mut [BodyState],
        inv_h: Real,
        push_max: Real,
    ) {
        let (ia, ib) = (self.state_a as usize, self.state_b as usize);
        let (sa, sb) = (&states[ia], &states[ib]);
        let (mut a, da) = (Velocity::of(sa), Delta::of(sa));
        let (mut b, db) = (Velocity::of(sb), Delta::of(sb));
        self.rows
            .solve::<USE_BIAS, BOTH_ORDERS>(&mut a, &da, &mut b, &db, inv_h, push_max);
        a.store(&mut states[ia]);
        b.store(&mut states[ib]);
    }

    /// [`ContactConstraint::solve_rows`] with its switches read at run
    /// time (the overflow's contacts differ in `both_orders`).
    #[inline(always)]
    pub(crate) fn solve_with(
        &mut self,
        states: &mut [BodyState],
        use_bias: bool,
        both_orders: bool,
        inv_h: Real,
        push_max: Real,
    ) {
        match (use_bias, both_orders) {
            (true, false) => self.solve_rows::<true, false>(states, inv_h, push_max),
            (false, false) => self.solve_rows::<false, false>(states, inv_h, push_max),
            (true, true) => self.solve_rows::<true, true>(states, inv_h, push_max),
            (false, true) => self.solve_rows::<false, true>(states, inv_h, push_max),
        }
    }

    /// The friction rows alone, one by one, from the bodies' velocities
    /// (after a coupled group has solved the normal rows):
    /// [`ContactRows::friction_row`] with the velocities updated after
    /// each row.
    pub(crate) fn solve_friction_rows(&mut self, states: &mut [BodyState]) {
        let (ia, ib) = (self.state_a as usize, self.state_b as usize);
        let [m_a, i_a, m_b, i_b] = self.applied_masses();
        let t = self.tangent();
        for i in 0..self.point_count() {
            let row = i + MAX_MANIFOLD_POINTS;
            let (ja, jb) = (self.rows.ja[row], self.rows.jb[row]);
            let (sa, sb) = (&states[ia], &states[ib]);
            let c_dot = (sb.v - sa.v).dot(t) + (sb.w * jb - sa.w * ja);
            let d = self
                .rows
                .friction_row(row, self.rows.friction_target(c_dot));
            let p = d * t;
            states[ia].v -= m_a * p;
            states[ia].w -= i_a * d * ja;
            states[ib].v += m_b * p;
            states[ib].w += i_b * d * jb;
        }
        if self.rows.surface.is_some() {
            let d = self.rows.rolling_row(states[ib].w - states[ia].w);
            states[ia].w -= i_a * d;
            states[ib].w += i_b * d;
        }
    }

    /// Sets the contact's surface terms (see
    /// [`ContactLane`](janus2d_core::contact_input::ContactLane)): the
    /// friction rows' target relative tangent speed, m/s, and the rolling
    /// row's bound per unit normal impulse (rolling resistance × rolling
    /// radius), m. Zero for both (the default) adds no row.
    ///
    /// ```
    /// use janus2d_constraints::contact::{ContactConstraint, ContactPointInput};
    /// use janus2d_core::{BodyHandle, Vec2};
    /// let h = BodyHandle::new(0, 0, 0);
    /// let point = ContactPointInput::default();
    /// let mut c = ContactConstraint::new(h, h, Vec2::Y, &[point], 0.6, 0.0, 0);
    /// assert_eq!(c.surface(), (0.0, 0.0));
    /// c.set_surface(2.0, 0.05);
    /// assert_eq!(c.surface(), (2.0, 0.05));
    /// ```
    pub fn set_surface(&mut self, tangent_speed: Real, rolling_resistance: Real) {
        self.rows.set_surface(0, tangent_speed, rolling_resistance);
    }

    /// The surface terms `(tangent speed, rolling bound)` (see
    /// [`ContactConstraint::set_surface`]).
    #[must_use]
    pub fn surface(&self) -> (Real, Real) {
        self.rows
            .surface
            .as_deref()
            .map_or((0.0, 0.0), |s| (s.tangent_speed, s.rolling_resistance))
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
            let (rn_a, rn_b) = (self.rows.ja[i], self.rows.jb[i]);
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
            // The solve's mass scale is 1 − s_i (with_mass_ratio's own).
            if soft.impulse_scale < self.rows.impulse_scale[i] {
                self.rows.impulse_scale[i] = soft.impulse_scale;
            }
        }
    }
}

impl Constraint for ContactConstraint {
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        // Static, sleeping and stale bodies read the identity state 0.
        self.state_a = bodies.state_index(self.body_a).unwrap_or(0);
        self.state_b = bodies.state_index(self.body_b).unwrap_or(0);
        let ma = bodies.inv_masses_at(self.state_a);
        let mb = bodies.inv_masses_at(self.state_b);
        let r = &mut self.rows;
        (r.inv_mass_a, r.inv_inertia_a) = (ma.inv_mass, ma.inv_inertia);
        (r.inv_mass_b, r.inv_inertia_b) = (mb.inv_mass, mb.inv_inertia);
        self.prepare_rows(ctx, bodies, self.applied_masses());
    }

    fn warm_start(&mut self, _ctx: &StepContext, states: &mut [BodyState]) {
        self.apply_warm_start(states);
    }

    fn solve(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        let (inv_h, push_max) = (ctx.inv_h, ctx.contact_push_max_velocity);
        self.solve_with(states, use_bias, false, inv_h, push_max);
    }

    fn apply_restitution(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        if !self.rows.has_restitution() {
            return;
        }
        let (ia, ib) = (self.state_a as usize, self.state_b as usize);
        let mut a = Velocity::of(&states[ia]);
        let mut b = Velocity::of(&states[ib]);
        self.rows
            .restitution(&mut a, &mut b, ctx.restitution_threshold);
        a.store(&mut states[ia]);
        b.store(&mut states[ib]);
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
        let (ja, jb) = (&self.rows.ja, &self.rows.jb);
        for (axis, first) in [(self.normal(), 0), (self.tangent(), MAX_MANIFOLD_POINTS)] {
            for i in 0..count {
                let row = first + i;
                let first_row = out.rows.len();
                let (j_a, j_b) = (ja[row], jb[row]);
                let (c, softness, lower, upper) = if first == 0 {
                    // At the start of the step: r · n = −(r × t).
                    let s = self.rows.base_separation[i] - (jb[i + 2] - ja[i + 2]);
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
                    let m = self.rows.friction * self.rows.impulse[i];
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
                    impulse: self.rows.impulse[row],
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

pub use janus2d_core::material::{mix_friction, mix_restitution};

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
        // The solve's mass scale 1 − s_i and impulse scale s_i come from
        // the same softness.
        assert_eq!(1.0 - c.rows.impulse_scale[0], normal.mass_scale);
        assert_eq!(c.rows.impulse_scale[0], normal.impulse_scale);
    }
}
