//! The mouse (target) joint: pulls a point of body b toward a world target
//! through a spring of bounded force, and damps b's rotation (Box2D's
//! mouse joint). Body a only gives the joint its second end (usually a
//! static ground): no row acts on it.
//!
//! # Derivation
//!
//! Body `b` with centre `x_b`, angle `θ_b`, anchor
//! `r_b = R(θ_b)(l_b − c_b)` from its centre of mass, and a world target `t`.
//!
//! **Point (2 rows).** `C = x_b + r_b − t`, `Ċ = v_b + ω_b × r_b`:
//!
//! ```text
//! J = [ 0  0 │ I  perp(r_b) ]
//! K = J M⁻¹ Jᵀ = m_b⁻¹ I + i_b⁻¹ perp(r_b) perp(r_b)ᵀ
//! ```
//!
//! solved as a 2×2 block with the spring's soft step
//! (`Softness::new(hertz, damping_ratio, h)`), in the relax pass too (a
//! spring is a force); the accumulated impulse's length is clamped to
//! `max_force · h`, so the pull never exceeds `max_force`.
//!
//! **Angular damping (1 row, optional).** `Ċ = ω_b`, `J = [0 0 │ 0 1]`,
//! `K = i_b⁻¹`, with no position term: the soft step of
//! `Softness::new(angular_hertz, angular_damping_ratio, h)` toward `ω_b = 0`
//! (Box2D 3.2 uses 0.5 Hz, 0.1): the dragged body stops spinning.
//!
//! An impulse `λ Jᵀ` moves only body b: it is an external impulse `P` at
//! the anchor `x_b + r_b` (linear momentum changes by `P`, angular
//! momentum about the origin by `(x_b + r_b) × P` plus the damping row's
//! `λ_θ`). With `J_a = 0` a dynamic body a is never pushed.
//!
//! **Moving the target**: set [`MouseJointDef::target`] and pass the
//! definition to `World::set_joint_def(handle, def.into())` (it keeps the
//! impulses and wakes the body; the world checks it with
//! [`Joint::set_def`](crate::Joint::set_def), as here):
//!
//! ```
//! use janus2d_constraints::{Joint, MouseJoint, MouseJointDef};
//! use janus2d_core::{BodyDef, BodySet, Vec2};
//! let mut bodies = BodySet::new();
//! let ground = bodies.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
//! let ball = bodies.create(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
//! let mut joint = Joint::new(MouseJointDef::new(ground, ball, Vec2::new(0.0, 1.0), 1000.0).into());
//! let mut def = joint.of::<MouseJoint>().unwrap().def().clone();
//! def.target = Vec2::new(2.0, 1.0);
//! joint.set_def(def.into()).unwrap();
//! assert_eq!(joint.of::<MouseJoint>().unwrap().def().target, Vec2::new(2.0, 1.0));
//! ```

use janus2d_core::body::{BodyHandle, BodySet, BodyState, InvMass};
use janus2d_core::constraint::{Block, Constraint, ConstraintRows, StepContext};
use janus2d_core::limits::MAX_COORDINATE;
use janus2d_core::math::{Real, Rot, Vec2, vec_is_finite};
use janus2d_core::softness::Softness;

use crate::joint_base::{JointBase, RowsAt};
use crate::joint_def::{JointDefBase, KindDef};
use crate::joint_rows::{RowSolve, WarmSide};
use crate::kind_rows::KindRows;
use crate::parts::{PairMass, PointPart};
use crate::{JointError, check_spring};

/// Everything needed to create a mouse joint.
///
/// ```
/// use janus2d_constraints::{JointError, MouseJointDef};
/// use janus2d_core::{BodyDef, BodySet, Vec2};
/// let mut bodies = BodySet::new();
/// let ground = bodies.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// let b = bodies.create(&BodyDef::dynamic(Vec2::new(1.0, 2.0))).unwrap();
/// // Grab b at the world point (1.5, 2.0), pull with at most 500 N.
/// let def = MouseJointDef::at_world_point(&bodies, ground, b, Vec2::new(1.5, 2.0), 500.0).unwrap();
/// assert_eq!(def.base.local_frame_b.anchor, Vec2::new(0.5, 0.0));
/// assert_eq!(def.target, Vec2::new(1.5, 2.0));
/// assert_eq!((def.hertz, def.damping_ratio), (5.0, 0.7));
/// assert!(def.validate().is_ok());
/// let mut bad = def.clone();
/// bad.max_force = -1.0;
/// assert_eq!(bad.validate(), Err(JointError::Negative));
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MouseJointDef {
    /// Bodies (a: the reference end, usually a static ground, never
    /// pushed; b: the dragged body), frames (frame b's anchor is the
    /// grabbed point; frame a is not used) and shared settings.
    pub base: JointDefBase,
    /// The world point the grabbed point is pulled toward, m.
    pub target: Vec2,
    /// Stiffness of the pull, Hz (default 5; 0: the point is only slowed,
    /// not pulled).
    pub hertz: Real,
    /// Damping ratio of the pull (dimensionless, default 0.7).
    pub damping_ratio: Real,
    /// Largest pulling force, N (≥ 0; `∞` allowed).
    pub max_force: Real,
    /// Stiffness of the angular damping row, Hz (default 0.5; 0: no
    /// angular damping).
    pub angular_hertz: Real,
    /// Damping ratio of the angular damping row (dimensionless, default 0.1).
    pub angular_damping_ratio: Real,
}

impl Default for MouseJointDef {
    /// A mouse joint toward the origin with no force (set `target` and `max_force`) between two placeholder bodies
    /// ([`JointDefBase::default`]: set `base.body_a` and `base.body_b`
    /// before use; `validate` refuses the placeholders as one body).
    fn default() -> Self {
        Self::from_base(JointDefBase::default(), Vec2::ZERO, 0.0)
    }
}

impl MouseJointDef {
    /// Pulls the point `local_anchor_b` (m, in b's frame) of `body_b`
    /// toward `target` (m, world) with at most `max_force` (N); body a is
    /// the reference end. Spring 5 Hz, damping 0.7, angular damping on.
    pub fn new(body_a: BodyHandle, body_b: BodyHandle, target: Vec2, max_force: Real) -> Self {
        Self::from_base(JointDefBase::new(body_a, body_b), target, max_force)
    }

    /// Grabs `body_b` at the world point `point` (m) at its current pose,
    /// the target at that point: the joint pulls nothing until the target
    /// moves (`Err(UnknownBody)` for a body not in `bodies`).
    pub fn at_world_point(
        bodies: &BodySet,
        body_a: BodyHandle,
        body_b: BodyHandle,
        point: Vec2,
        max_force: Real,
    ) -> Result<Self, JointError> {
        if !vec_is_finite(point) {
            return Err(JointError::NonFinite);
        }
        let xf = bodies.sim(body_b).ok_or(JointError::UnknownBody)?.transform;
        bodies.sim(body_a).ok_or(JointError::UnknownBody)?;
        let mut def = Self::new(body_a, body_b, point, max_force);
        def.base.local_frame_b.anchor = xf.apply_inv(point);
        Ok(def)
    }

    /// The joint on a shared base (frame b's anchor is the grabbed point).
    pub fn from_base(base: JointDefBase, target: Vec2, max_force: Real) -> Self {
        MouseJointDef {
            base,
            target,
            hertz: 5.0,
            damping_ratio: 0.7,
            max_force,
            angular_hertz: 0.5,
            angular_damping_ratio: 0.1,
        }
    }

    /// Sets the pull's spring, Hz and damping ratio (builder style).
    pub fn with_spring(mut self, hertz: Real, damping_ratio: Real) -> Self {
        self.hertz = hertz;
        self.damping_ratio = damping_ratio;
        self
    }

    /// Sets the angular damping row, Hz (0: off) and damping ratio
    /// (builder style).
    pub fn with_angular_damping(mut self, hertz: Real, damping_ratio: Real) -> Self {
        self.angular_hertz = hertz;
        self.angular_damping_ratio = damping_ratio;
        self
    }

    /// Moves the target, m (builder style; on a live joint, pass the
    /// definition to `World::set_joint_def`).
    pub fn with_target(mut self, target: Vec2) -> Self {
        self.target = target;
        self
    }

    /// Checks the definition's own values (not the handles): a finite
    /// target within [`MAX_COORDINATE`] ([`JointError::OutOfBounds`]),
    /// finite springs within the spring bounds, a non-negative (non-NaN)
    /// `max_force`.
    pub fn validate(&self) -> Result<(), JointError> {
        self.base.validate()?;
        let finite = vec_is_finite(self.target)
            && self.hertz.is_finite()
            && self.damping_ratio.is_finite()
            && self.angular_hertz.is_finite()
            && self.angular_damping_ratio.is_finite()
            && !self.max_force.is_nan();
        if !finite {
            return Err(JointError::NonFinite);
        }
        if self.hertz < 0.0
            || self.damping_ratio < 0.0
            || self.angular_hertz < 0.0
            || self.angular_damping_ratio < 0.0
            || self.max_force < 0.0
        {
            return Err(JointError::Negative);
        }
        if self.target.x.abs() > MAX_COORDINATE || self.target.y.abs() > MAX_COORDINATE {
            return Err(JointError::OutOfBounds {
                field: "target",
                min: -MAX_COORDINATE,
                max: MAX_COORDINATE,
            });
        }
        check_spring(self.hertz, self.damping_ratio)?;
        check_spring(self.angular_hertz, self.angular_damping_ratio)
    }
}

impl KindDef for MouseJointDef {
    fn base(&self) -> &JointDefBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointDefBase {
        &mut self.base
    }
    fn validate(&self) -> Result<(), JointError> {
        MouseJointDef::validate(self)
    }
}

/// A mouse joint in solver form.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(C)]
pub struct MouseJoint {
    /// State indices, masses and switches the solver reads.
    pub(crate) base: JointBase,
    /// The definition it was made from (the target as last set).
    pub(crate) def: Box<MouseJointDef>,
    /// Anchor on b relative to b's centre at the start of the step (world
    /// frame), m.
    frame_b: Vec2,
    /// `c_b − target` at the start of the step, m.
    delta_center: Vec2,
    /// Accumulated point impulse on b, N·s.
    linear_impulse: Vec2,
    /// Accumulated angular damping impulse on b, N·m·s.
    angular_impulse: Real,
    /// Softness of the pull for this step.
    linear_softness: Softness,
    /// Softness of the angular damping for this step.
    angular_softness: Softness,
}

/// Body b's inverse masses alone, as a pair (body a's share zero): the
/// rows' `K` has no term from a.
fn b_only(m: &PairMass) -> PairMass {
    PairMass {
        a: InvMass::ZERO,
        b: m.b,
    }
}

impl MouseJoint {
    /// A joint from a definition (validate it first).
    pub fn new(def: MouseJointDef) -> Self {
        MouseJoint {
            def: Box::new(def),
            base: JointBase::default(),
            frame_b: Vec2::ZERO,
            delta_center: Vec2::ZERO,
            linear_impulse: Vec2::ZERO,
            angular_impulse: 0.0,
            linear_softness: Softness::RIGID,
            angular_softness: Softness::RIGID,
        }
    }

    /// True when the angular damping row acts.
    fn has_angular_row(&self) -> bool {
        self.def.angular_hertz > 0.0
    }

    /// Rows this joint adds to the solver when enabled: the two point rows
    /// and the angular damping row when it is on.
    #[must_use]
    pub fn row_count(&self) -> usize {
        2 + usize::from(self.has_angular_row())
    }

    /// Carries the accumulated impulses through a portal when both ends
    /// move to the other side: the point impulse turns by `rotation = Q`
    /// and scales by `scale = 1/η` (as the revolute joint's), the angular
    /// one is kept. The target is a world point the caller owns: it is not
    /// mapped (move it with `World::set_joint_def`).
    pub fn carry_through_portal(&mut self, rotation: Rot, scale: Real) {
        self.linear_impulse = scale * rotation.rotate(self.linear_impulse);
    }

    /// The grabbed point on b in the world, m.
    pub fn world_anchor(&self, bodies: &BodySet) -> Vec2 {
        self.def.base.world_anchors(bodies).1
    }

    /// Distance from the grabbed point to the target, m.
    pub fn error(&self, bodies: &BodySet) -> Real {
        (self.world_anchor(bodies) - self.def.target).length()
    }

    /// False when the joint is disabled (skipped by the solver).
    #[must_use]
    pub fn is_enabled(&self) -> bool {
        self.base.enabled
    }

    /// Point impulse on b of one substep of the last solved step, N·s.
    #[must_use]
    pub fn linear_impulse(&self) -> Vec2 {
        self.linear_impulse
    }

    /// Angular damping impulse on b of one substep of the last solved
    /// step, N·m·s.
    #[must_use]
    pub fn angular_impulse(&self) -> Real {
        self.angular_impulse
    }

    /// Force the joint applies to body b over the last solved step, N (at
    /// most `max_force` long; nothing acts on body a).
    #[must_use]
    pub fn constraint_force(&self) -> Vec2 {
        self.linear_impulse * self.base.inv_h
    }

    /// Torque of the angular damping on body b over the last solved step,
    /// N·m.
    #[must_use]
    pub fn constraint_torque(&self) -> Real {
        self.angular_impulse * self.base.inv_h
    }
}

impl KindRows for MouseJoint {
    fn base(&self) -> &JointBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointBase {
        &mut self.base
    }
    fn row_count(&self) -> usize {
        MouseJoint::row_count(self)
    }
    fn is_driven(&self) -> bool {
        self.def.max_force > 0.0
    }
    fn constraint_force(&self) -> Vec2 {
        MouseJoint::constraint_force(self)
    }
    fn constraint_torque(&self) -> Real {
        MouseJoint::constraint_torque(self)
    }
    fn carry_through_portal(&mut self, rotation: Rot, scale: Real) {
        MouseJoint::carry_through_portal(self, rotation, scale);
    }
    /// The kept impulses on body b (nothing on a): the spin row's, then
    /// the pull's at b's current arm.
    #[inline(always)]
    fn warm_rows(&self, w: &mut WarmSide<'_>) {
        w.spin_b(self.angular_impulse);
        w.target(self.frame_b, self.linear_impulse);
    }
    /// The angular damping, then the pull, on body b only.
    #[inline(always)]
    fn solve_rows(&mut self, ctx: &StepContext, _use_bias: bool, s: &mut RowSolve) {
        if self.has_angular_row() {
            s.spin_b(self.angular_softness, &mut self.angular_impulse);
        }
        let r_b = s.sb.dq.rotate(self.frame_b);
        let c = s.sb.dp + r_b + self.delta_center;
        let max_impulse = ctx.h * self.def.max_force;
        s.target(
            r_b,
            c,
            self.linear_softness,
            max_impulse,
            &mut self.linear_impulse,
        );
    }
}

impl Constraint for MouseJoint {
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        let Some((_, b)) = self
            .base
            .load(ctx, bodies, self.def.base.body_a, self.def.base.body_b)
        else {
            return;
        };
        let q_b = b.sim.transform.q;
        self.frame_b = q_b.rotate(self.def.base.local_frame_b.anchor - b.sim.local_center);
        self.delta_center = b.sim.center - self.def.target;
        self.linear_softness = Softness::new(self.def.hertz, self.def.damping_ratio, ctx.h);
        self.angular_softness = Softness::new(
            self.def.angular_hertz,
            self.def.angular_damping_ratio,
            ctx.h,
        );
        if !ctx.warm_starting {
            self.linear_impulse = Vec2::ZERO;
            self.angular_impulse = 0.0;
        }
        if !self.has_angular_row() {
            self.angular_impulse = 0.0;
        }
    }

    fn warm_start(&mut self, _ctx: &StepContext, states: &mut [BodyState]) {
        crate::kind_rows::warm_start_states(self, states);
    }

    fn solve(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        crate::kind_rows::solve_states(self, ctx, states, use_bias);
    }

    fn rows(&self, ctx: &StepContext, bodies: &BodySet) -> ConstraintRows {
        let at = RowsAt::new(bodies, &self.def.base);
        let b = bodies.solver_body(self.def.base.body_b);
        let c = b.sim.center + at.r_b - self.def.target;
        let m = b_only(&at.m);
        let soft = Softness::new(self.def.hertz, self.def.damping_ratio, ctx.h);
        let max = ctx.h * self.def.max_force;
        let mut out = ConstraintRows::default();
        for (axis, c, impulse) in [
            (Vec2::X, c.x, self.linear_impulse.x),
            (Vec2::Y, c.y, self.linear_impulse.y),
        ] {
            let mut row = at.point_row(axis, c, soft, impulse);
            row.jacobian[0].linear = Vec2::ZERO;
            row.jacobian[0].angular = 0.0;
            (row.lower, row.upper) = (-max, max);
            out.rows.push(row);
        }
        let (k11, k12, k22) = PointPart::effective_mass(&m, Vec2::ZERO, at.r_b);
        out.blocks.push(Block {
            first_row: 0,
            len: 2,
            k: [[k11, k12, 0.0], [k12, k22, 0.0], [0.0; 3]],
        });
        if self.has_angular_row() {
            let soft = Softness::new(
                self.def.angular_hertz,
                self.def.angular_damping_ratio,
                ctx.h,
            );
            let free = (Real::NEG_INFINITY, Real::INFINITY);
            let mut row = at.angle_row(1.0, 0.0, soft, free, self.angular_impulse);
            row.jacobian[0].angular = 0.0;
            out.blocks.push(Block {
                first_row: 2,
                len: 1,
                k: [[m.b.inv_inertia, 0.0, 0.0], [0.0; 3], [0.0; 3]],
            });
            out.rows.push(row);
        }
        out
    }

    fn is_enabled(&self) -> bool {
        self.base.enabled
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use janus2d_core::body::BodyDef;
    use janus2d_core::solver::SolverSettings;

    #[test]
    fn the_warm_start_leaves_body_a_alone() {
        let mut set = BodySet::new();
        let a = set
            .create(&BodyDef::dynamic(Vec2::new(-1.0, 0.5)).with_mass(3.0, 0.2))
            .unwrap();
        let b = set
            .create(
                &BodyDef::dynamic(Vec2::new(0.7, 0.2))
                    .with_mass(0.5, 0.05)
                    .with_angle(0.8),
            )
            .unwrap();
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
        let mut def = MouseJointDef::new(a, b, Vec2::new(2.0, 1.0), 100.0);
        def.base.local_frame_b.anchor = Vec2::new(0.2, -0.1);
        let mut joint = MouseJoint::new(def);
        joint.prepare(&ctx, &set);
        joint.linear_impulse = Vec2::new(0.4, -0.3);
        joint.angular_impulse = 0.02;
        let mut whole = set.states.clone();
        joint.warm_start(&ctx, &mut whole);
        let sa = joint.base.state_a as usize;
        assert_eq!(
            (whole[sa].v, whole[sa].w),
            (set.states[sa].v, set.states[sa].w)
        );
        assert_eq!(joint.rows(&ctx, &set).rows.len(), 3);
        let quiet = MouseJoint::new(joint.def.clone().with_angular_damping(0.0, 0.0));
        assert_eq!(quiet.row_count(), 2);
    }
}
