//! The wheel joint: body b's anchor (a wheel's hub) moves along a
//! suspension axis fixed in body a (a chassis) on a spring, and b turns
//! freely about it; optional translation limits and a rotational motor.
//!
//! # Derivation
//!
//! The geometry is the prismatic joint's ([`crate::prismatic`]): anchors
//! `r_a`, `r_b` from the centres of mass, `d = (x_b + r_b) − (x_a + r_a)`,
//! the suspension axis `n` = frame a's x axis turning with a, its normal
//! `perp = perp(n)`.
//!
//! **Perpendicular row (rigid).** `C_⊥ = perp · d`,
//! `J_⊥ = [ −perp  −(r_a + d) × perp │ perp  r_b × perp ]`, its softness
//! [`JointDefBase::rigid_softness`] on the inverse masses and its bias
//! capped at the joint correction speed, solved alone (the wheel has no
//! angle row to pair it with).
//!
//! **Axial rows.** The translation `t = n · d`,
//! `J_t = [ −n  −(r_a + d) × n │ n  r_b × n ]`. The suspension spring
//! drives `t` to zero with `Softness::new(hertz, damping_ratio, h)` (in
//! the relax pass too: a spring is a force; 0 Hz exerts none), and the
//! optional limits are the one-sided rows `t − lower ≥ 0`,
//! `upper − t ≥ 0`, speculative while apart, at the rigid rows' softness.
//!
//! **Motor (angular).** `J = [ 0 −1 │ 0 1 ]`, `K = i_a + i_b`: drives
//! `ω_b − ω_a` to `motor_speed` with the impulse clamped to
//! `max_motor_torque · h`, an [`AnglePart`] motor row.
//!
//! There is no angle row: the wheel spins. As the prismatic joint, the
//! joint keeps its last iteration's rows for the warm start's per-body
//! shares (they are the current positions' after the relax iteration).

use janus2d_core::body::{BodyHandle, BodySet, BodyState};
use janus2d_core::constraint::{Block, Constraint, ConstraintRows, StepContext};
use janus2d_core::math::{Real, Rot, Vec2};
use janus2d_core::softness::Softness;

use crate::joint_base::{JointBase, RowsAt};
use crate::joint_def::{JointDefBase, JointFrame, KindDef, LimitsMut, MotorMut, SpringMut};
use crate::joint_rows::{Bounds, RowSolve, Terms, WarmSide};
use crate::kind_rows::{GeneralRows, KindRows, TreeRows};
use crate::parts::{AnglePart, AxisPart, AxisRow};
use crate::prismatic::{SlideFrame, check_translation, row_speed, slide_rows_at};
use crate::{JointError, check_motor_speed, check_spring};

/// Box2D's default suspension stiffness, Hz.
pub const DEFAULT_WHEEL_HERTZ: Real = 1.0;
/// Box2D's default suspension damping ratio.
pub const DEFAULT_WHEEL_DAMPING_RATIO: Real = 0.7;

/// Everything needed to create a wheel joint.
///
/// ```
/// use janus2d_constraints::{JointError, WheelJointDef};
/// use janus2d_core::{BodyDef, BodySet, Vec2};
/// let mut bodies = BodySet::new();
/// let chassis = bodies.create(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
/// let wheel = bodies.create(&BodyDef::dynamic(Vec2::new(-1.0, 0.4))).unwrap();
/// // A vertical suspension at the hub, 5 Hz, driven at −20 rad/s by up to 50 N·m.
/// let def = WheelJointDef::at_world(&bodies, chassis, wheel, Vec2::new(-1.0, 0.4), Vec2::Y)
///     .unwrap()
///     .with_spring(5.0, 0.7)
///     .with_motor(-20.0, 50.0);
/// assert!(def.enable_spring);
/// assert!(def.validate().is_ok());
/// assert_eq!(def.with_limits(0.1, -0.1).validate(), Err(JointError::InvalidLimits));
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct WheelJointDef {
    /// Bodies, frames (the anchors; frame a's x axis is the suspension
    /// axis; frame b's angle is unused) and shared settings.
    pub base: JointDefBase,
    /// Enables the suspension spring (default true).
    pub enable_spring: bool,
    /// Suspension stiffness, Hz (default 1; 0: no spring force).
    pub hertz: Real,
    /// Suspension damping ratio (dimensionless, default 0.7).
    pub damping_ratio: Real,
    /// Enables the translation limits.
    pub enable_limit: bool,
    /// Lower translation limit along the axis, m.
    pub lower_translation: Real,
    /// Upper translation limit along the axis, m.
    pub upper_translation: Real,
    /// Enables the motor.
    pub enable_motor: bool,
    /// Motor target speed `ω_b − ω_a`, rad/s.
    pub motor_speed: Real,
    /// Maximum motor torque, N·m (finite, ≥ 0).
    pub max_motor_torque: Real,
}

impl Default for WheelJointDef {
    /// A wheel on frame a's x axis with the default suspension between two placeholder bodies
    /// ([`JointDefBase::default`]: set `base.body_a` and `base.body_b`
    /// before use; `validate` refuses the placeholders as one body).
    fn default() -> Self {
        Self::from_base(JointDefBase::default())
    }
}

impl WheelJointDef {
    /// A wheel at the given local anchors with the suspension along
    /// `local_axis_a` (in a's frame, any nonzero length; zero is the x
    /// axis), the spring at Box2D's defaults (1 Hz, 0.7).
    pub fn new(
        body_a: BodyHandle,
        body_b: BodyHandle,
        local_anchor_a: Vec2,
        local_anchor_b: Vec2,
        local_axis_a: Vec2,
    ) -> Self {
        let angle = if local_axis_a == Vec2::ZERO {
            0.0
        } else {
            local_axis_a.y.atan2(local_axis_a.x)
        };
        Self::from_base(JointDefBase::with_frames(
            body_a,
            body_b,
            JointFrame::new(local_anchor_a, angle),
            JointFrame::at(local_anchor_b),
        ))
    }

    /// A wheel at a world point (the hub) with the suspension along a
    /// world axis (any nonzero length). `Err(ZeroLength)` for a zero
    /// axis, `Err(NonFinite)`, `Err(UnknownBody)`.
    pub fn at_world(
        bodies: &BodySet,
        body_a: BodyHandle,
        body_b: BodyHandle,
        point: Vec2,
        axis: Vec2,
    ) -> Result<Self, JointError> {
        if !janus2d_core::math::vec_is_finite(axis) {
            return Err(JointError::NonFinite);
        }
        if axis == Vec2::ZERO {
            return Err(JointError::ZeroLength);
        }
        let angle = axis.y.atan2(axis.x);
        Ok(Self::from_base(JointDefBase::at_world_frame(
            bodies, body_a, body_b, point, angle,
        )?))
    }

    /// A wheel on a shared base (frames, thresholds, softness), the spring
    /// on at Box2D's defaults, no limits, no motor.
    pub fn from_base(base: JointDefBase) -> Self {
        WheelJointDef {
            base,
            enable_spring: true,
            hertz: DEFAULT_WHEEL_HERTZ,
            damping_ratio: DEFAULT_WHEEL_DAMPING_RATIO,
            enable_limit: false,
            lower_translation: 0.0,
            upper_translation: 0.0,
            enable_motor: false,
            motor_speed: 0.0,
            max_motor_torque: 0.0,
        }
    }

    /// Lets the two bodies collide (builder style).
    pub fn with_collide_connected(mut self, on: bool) -> Self {
        self.base.collide_connected = on;
        self
    }

    /// Enables the suspension spring: stiffness Hz, damping ratio
    /// (builder style).
    pub fn with_spring(mut self, hertz: Real, damping_ratio: Real) -> Self {
        self.enable_spring = true;
        self.hertz = hertz;
        self.damping_ratio = damping_ratio;
        self
    }

    /// Enables the translation limits, m (builder style).
    pub fn with_limits(mut self, lower: Real, upper: Real) -> Self {
        self.enable_limit = true;
        self.lower_translation = lower;
        self.upper_translation = upper;
        self
    }

    /// Enables the motor: speed rad/s, largest torque N·m (builder style).
    pub fn with_motor(mut self, speed: Real, max_torque: Real) -> Self {
        self.enable_motor = true;
        self.motor_speed = speed;
        self.max_motor_torque = max_torque;
        self
    }

    /// Checks the definition's own values (not the handles): the base,
    /// finite values, `lower ≤ upper` when the limits are on, non-negative
    /// torque, stiffness and damping, translations within
    /// [`MAX_EXTENT`](janus2d_core::limits::MAX_EXTENT), the speed within
    /// [`MAX_ANGULAR_SPEED`](janus2d_core::limits::MAX_ANGULAR_SPEED).
    pub fn validate(&self) -> Result<(), JointError> {
        self.base.validate()?;
        let finite = self.lower_translation.is_finite()
            && self.upper_translation.is_finite()
            && self.motor_speed.is_finite()
            && self.max_motor_torque.is_finite()
            && self.hertz.is_finite()
            && self.damping_ratio.is_finite();
        if !finite {
            return Err(JointError::NonFinite);
        }
        if self.enable_limit && self.lower_translation > self.upper_translation {
            return Err(JointError::InvalidLimits);
        }
        if self.max_motor_torque < 0.0 || self.hertz < 0.0 || self.damping_ratio < 0.0 {
            return Err(JointError::Negative);
        }
        check_translation(self.lower_translation, "lower_translation")?;
        check_translation(self.upper_translation, "upper_translation")?;
        check_motor_speed(self.motor_speed)?;
        check_spring(self.hertz, self.damping_ratio)
    }
}

impl KindDef for WheelJointDef {
    fn base(&self) -> &JointDefBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointDefBase {
        &mut self.base
    }
    fn validate(&self) -> Result<(), JointError> {
        WheelJointDef::validate(self)
    }
    fn limits_mut(&mut self) -> Option<LimitsMut<'_>> {
        Some(LimitsMut {
            enable: &mut self.enable_limit,
            lower: &mut self.lower_translation,
            upper: &mut self.upper_translation,
        })
    }
    fn motor_mut(&mut self) -> Option<MotorMut<'_>> {
        Some(MotorMut {
            enable: &mut self.enable_motor,
            speed: &mut self.motor_speed,
            max: &mut self.max_motor_torque,
            linear: false,
        })
    }
    fn spring_mut(&mut self) -> Option<SpringMut<'_>> {
        Some(SpringMut {
            enable: &mut self.enable_spring,
            hertz: &mut self.hertz,
            damping_ratio: &mut self.damping_ratio,
        })
    }
}

/// A wheel joint in solver form.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(C)]
pub struct WheelJoint {
    /// State indices, masses and switches the solver reads.
    pub(crate) base: JointBase,
    /// The definition it was made from (spring, limits and motor settings).
    pub(crate) def: Box<WheelJointDef>,
    /// The geometry at the start of the step.
    frame: SlideFrame,
    /// The perpendicular row of the last iteration (the warm start's).
    perp_row: AxisRow,
    /// The axial row of the last iteration (the warm start's).
    axial_row: AxisRow,
    /// Accumulated perpendicular impulse, N·s.
    perp_impulse: Real,
    spring: AxisPart,
    lower: AxisPart,
    upper: AxisPart,
    motor: AnglePart,
    /// Softness of the perpendicular row (and the limits) this step.
    linear_softness: Softness,
    /// Softness of the suspension spring this step.
    spring_softness: Softness,
}

impl WheelJoint {
    /// A joint from a definition (validate it first).
    pub fn new(def: WheelJointDef) -> Self {
        WheelJoint {
            def: Box::new(def),
            base: JointBase::default(),
            frame: SlideFrame::default(),
            perp_row: AxisRow::default(),
            axial_row: AxisRow::default(),
            perp_impulse: 0.0,
            spring: AxisPart::default(),
            lower: AxisPart::default(),
            upper: AxisPart::default(),
            motor: AnglePart::default(),
            linear_softness: Softness::RIGID,
            spring_softness: Softness::RIGID,
        }
    }

    /// Rows this joint adds to the solver when enabled: the perpendicular
    /// row, the spring, motor and two limit rows when on.
    #[must_use]
    pub fn row_count(&self) -> usize {
        1 + usize::from(self.def.enable_spring)
            + usize::from(self.def.enable_motor)
            + 2 * usize::from(self.def.enable_limit)
    }

    /// Carries the accumulated impulses through a portal when both ends
    /// move to the other side: the linear rows' impulses scale by
    /// `scale = 1/η` (their directions turn with body a's clone); the
    /// motor's angular impulse is kept; the translation limits scale by
    /// `η`, as translations along the axis do.
    pub fn carry_through_portal(&mut self, _rotation: Rot, scale: Real) {
        // The anchors scale by η about each copy's centre of mass, so
        // translations along the axis do the same.
        let eta = 1.0 / scale;
        self.def.lower_translation *= eta;
        self.def.upper_translation *= eta;
        self.perp_impulse *= scale;
        for part in [&mut self.spring, &mut self.lower, &mut self.upper] {
            part.impulse *= scale;
        }
    }

    /// The suspension's translation `t = n · d` at the bodies' current
    /// poses, m.
    #[must_use]
    pub fn translation(&self, bodies: &BodySet) -> Real {
        slide_rows_at(bodies, &self.def.base).1.translation
    }

    /// The perpendicular error `C_⊥ = perp · d` at the bodies' current
    /// poses, m (0 when the hub is on the suspension axis).
    #[must_use]
    pub fn perpendicular_error(&self, bodies: &BodySet) -> Real {
        slide_rows_at(bodies, &self.def.base).1.c_perp
    }

    /// The suspension's speed `ṫ` at the bodies' current velocities, m/s.
    #[must_use]
    pub fn translation_speed(&self, bodies: &BodySet) -> Real {
        let (_, rows) = slide_rows_at(bodies, &self.def.base);
        row_speed(bodies, &self.def.base, &rows.axial)
    }

    /// The wheel's spin relative to a, `ω_b − ω_a`, rad/s.
    #[must_use]
    pub fn angular_speed(&self, bodies: &BodySet) -> Real {
        let w = |h| bodies.state(h).map_or(0.0, |s| s.w);
        w(self.def.base.body_b) - w(self.def.base.body_a)
    }

    /// False when the joint is disabled (skipped by the solver).
    #[must_use]
    pub fn is_enabled(&self) -> bool {
        self.base.enabled
    }

    /// The axial impulse of one substep of the last solved step (spring
    /// and limits, along `n`), N·s.
    #[must_use]
    pub fn axial_impulse(&self) -> Real {
        self.spring.impulse + self.lower.impulse - self.upper.impulse
    }

    /// The perpendicular impulse of one substep of the last solved step,
    /// N·s.
    #[must_use]
    pub fn perpendicular_impulse(&self) -> Real {
        self.perp_impulse
    }

    /// The motor's torque on b over the last solved step, N·m.
    #[must_use]
    pub fn motor_torque(&self) -> Real {
        self.motor.impulse * self.base.inv_h
    }

    /// Force the joint applies to body b over the last solved step, N
    /// (body a gets the opposite): the perpendicular and axial impulses
    /// as a world vector. Kept while both bodies sleep.
    #[must_use]
    pub fn constraint_force(&self) -> Vec2 {
        (self.perp_impulse * self.perp_row.n + self.axial_impulse() * self.axial_row.n)
            * self.base.inv_h
    }

    /// Torque the motor applies to body b over the last solved step, N·m
    /// (body a gets the opposite).
    #[must_use]
    pub fn constraint_torque(&self) -> Real {
        self.motor_torque()
    }
}

impl KindRows for WheelJoint {
    fn base(&self) -> &JointBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointBase {
        &mut self.base
    }
    fn row_count(&self) -> usize {
        WheelJoint::row_count(self)
    }
    fn is_driven(&self) -> bool {
        self.def.enable_motor && self.def.max_motor_torque > 0.0
    }
    fn constraint_force(&self) -> Vec2 {
        WheelJoint::constraint_force(self)
    }
    fn constraint_torque(&self) -> Real {
        WheelJoint::constraint_torque(self)
    }
    fn carry_through_portal(&mut self, rotation: Rot, scale: Real) {
        WheelJoint::carry_through_portal(self, rotation, scale);
    }
    /// The kept impulses along the rows of the last iteration: the axial
    /// rows' sum, the perpendicular row's, then the motor's angular one.
    #[inline(always)]
    fn warm_rows(&self, w: &mut WarmSide<'_>) {
        w.linear(&self.axial_row, self.axial_impulse());
        w.linear(&self.perp_row, self.perp_impulse);
        w.angle(self.motor.impulse);
    }
    /// Spring, motor, limits, then the perpendicular row (unless the tree
    /// solves it).
    #[inline(always)]
    fn solve_rows(&mut self, ctx: &StepContext, use_bias: bool, s: &mut RowSolve) {
        let rows = self.frame.rows(&s.sa, &s.sb, &s.m);
        let axial = rows.axial;
        let t = rows.translation;
        let cap = ctx.joint_max_correction_speed;
        if self.def.enable_spring && self.def.hertz > 0.0 {
            // The spring's impulse is clamped (not summed) though free.
            let free = Bounds::Clamp(Real::NEG_INFINITY, Real::INFINITY);
            let terms = Terms::soft(self.spring_softness, t, Real::INFINITY);
            s.linear(&axial, terms, free, &mut self.spring.impulse);
        }
        if self.def.enable_motor {
            let bounds = Bounds::symmetric(ctx.h * self.def.max_motor_torque);
            let terms = Terms::motor(self.def.motor_speed);
            s.angle(1.0, self.motor.mass, terms, bounds, &mut self.motor.impulse);
        }
        if self.def.enable_limit {
            let soft = self.linear_softness;
            let lower = Terms::limit(
                t - self.def.lower_translation,
                soft,
                ctx.inv_h,
                use_bias,
                cap,
            );
            s.linear(&axial, lower, Bounds::ONE_SIDED, &mut self.lower.impulse);
            let down = AxisRow {
                n: -axial.n,
                s_a: -axial.s_a,
                s_b: -axial.s_b,
                mass: axial.mass,
            };
            let upper = Terms::limit(
                self.def.upper_translation - t,
                soft,
                ctx.inv_h,
                use_bias,
                cap,
            );
            s.linear(&down, upper, Bounds::ONE_SIDED, &mut self.upper.impulse);
        }
        let perp = rows.perp;
        if !self.base.in_tree {
            let terms = Terms::equality(self.linear_softness, rows.c_perp, cap, use_bias);
            s.linear(&perp, terms, Bounds::Free, &mut self.perp_impulse);
        }
        self.perp_row = perp;
        self.axial_row = axial;
    }
    /// The perpendicular row joins the exact tree solve (rigid unless the
    /// joint has its own constraint softness); the suspension, limits and
    /// motor stay iterative, so it always has a Gauss–Seidel pass.
    #[inline(always)]
    fn tree_rows(&self) -> Option<TreeRows<'_>> {
        (self.def.base.constraint_hertz == 0.0).then_some(TreeRows::General { count: 1 })
    }
    #[inline(always)]
    fn tree_general_rows(&self, sa: &BodyState, sb: &BodyState) -> GeneralRows {
        let p = self.frame.rows(sa, sb, &self.base.masses);
        let c = p.c_perp;
        let p = p.perp;
        GeneralRows {
            count: 1,
            j_a: [[-p.n.x, -p.n.y, -p.s_a], [0.0; 3], [0.0; 3]],
            j_b: [[p.n.x, p.n.y, p.s_b], [0.0; 3], [0.0; 3]],
            c: [c, 0.0, 0.0],
            linear: [true, false, false],
            impulse: [self.perp_impulse, 0.0, 0.0],
        }
    }
    #[inline(always)]
    fn set_tree_impulses(&mut self, impulses: [Real; 3]) {
        self.perp_impulse = impulses[0];
    }
    #[inline(always)]
    fn has_iterative_rows(&self) -> bool {
        true
    }
}

impl Constraint for WheelJoint {
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        let Some((a, b)) = self
            .base
            .load(ctx, bodies, self.def.base.body_a, self.def.base.body_b)
        else {
            return;
        };
        self.frame = SlideFrame::prepare(&self.def.base, &a, &b);
        let m = self.base.masses;
        let rows = self
            .frame
            .rows(&BodyState::IDENTITY, &BodyState::IDENTITY, &m);
        self.perp_row = rows.perp;
        self.axial_row = rows.axial;
        self.motor.prepare(&m);
        self.linear_softness = self
            .def
            .base
            .rigid_softness(ctx, m.a.inv_mass, m.b.inv_mass);
        self.spring_softness = Softness::new(self.def.hertz, self.def.damping_ratio, ctx.h);
        if !ctx.warm_starting {
            self.perp_impulse = 0.0;
            self.spring.impulse = 0.0;
            self.lower.impulse = 0.0;
            self.upper.impulse = 0.0;
            self.motor.impulse = 0.0;
        }
        if !(self.def.enable_spring && self.def.hertz > 0.0) {
            self.spring.impulse = 0.0;
        }
        if !self.def.enable_motor {
            self.motor.impulse = 0.0;
        }
        if !self.def.enable_limit {
            self.lower.impulse = 0.0;
            self.upper.impulse = 0.0;
        }
    }

    fn warm_start(&mut self, _ctx: &StepContext, states: &mut [BodyState]) {
        crate::kind_rows::warm_start_states(self, states);
    }

    fn solve(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        crate::kind_rows::solve_states(self, ctx, states, use_bias);
    }

    fn rows(&self, ctx: &StepContext, bodies: &BodySet) -> ConstraintRows {
        let (at, rows): (RowsAt, _) = slide_rows_at(bodies, &self.def.base);
        let m = at.m;
        let linear = self
            .def
            .base
            .rigid_softness(ctx, m.a.inv_mass, m.b.inv_mass);
        let free = (Real::NEG_INFINITY, Real::INFINITY);
        let (i_a, i_b) = (m.a.inv_inertia, m.b.inv_inertia);
        let k_of = |row: &AxisRow| {
            m.a.inv_mass + m.b.inv_mass + i_a * row.s_a * row.s_a + i_b * row.s_b * row.s_b
        };
        let mut out = ConstraintRows::default();
        let mut push = |row: janus2d_core::constraint::Row, k: Real| {
            out.blocks.push(Block {
                first_row: out.rows.len(),
                len: 1,
                k: [[k, 0.0, 0.0], [0.0; 3], [0.0; 3]],
            });
            out.rows.push(row);
        };
        let perp = &rows.perp;
        push(
            at.axis_row(
                perp.n,
                (perp.s_a, perp.s_b),
                rows.c_perp,
                linear,
                free,
                self.perp_impulse,
            ),
            k_of(perp),
        );
        let axial = &rows.axial;
        let k_axial = k_of(axial);
        let t = rows.translation;
        let along = |sign: Real| (sign * axial.n, (sign * axial.s_a, sign * axial.s_b));
        if self.def.enable_spring {
            let (n, s) = along(1.0);
            push(
                at.axis_row(
                    n,
                    s,
                    t,
                    Softness::new(self.def.hertz, self.def.damping_ratio, ctx.h),
                    free,
                    self.spring.impulse,
                ),
                k_axial,
            );
        }
        if self.def.enable_motor {
            let max = ctx.h * self.def.max_motor_torque;
            push(
                at.angle_row(1.0, 0.0, Softness::RIGID, (-max, max), self.motor.impulse),
                i_a + i_b,
            );
        }
        if self.def.enable_limit {
            let up = (0.0, Real::INFINITY);
            let (n, s) = along(1.0);
            push(
                at.axis_row(
                    n,
                    s,
                    t - self.def.lower_translation,
                    linear,
                    up,
                    self.lower.impulse,
                ),
                k_axial,
            );
            let (n, s) = along(-1.0);
            push(
                at.axis_row(
                    n,
                    s,
                    self.def.upper_translation - t,
                    linear,
                    up,
                    self.upper.impulse,
                ),
                k_axial,
            );
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

    fn pair() -> (BodySet, BodyHandle, BodyHandle) {
        let mut set = BodySet::new();
        let a = set
            .create(&BodyDef::dynamic(Vec2::ZERO).with_mass(20.0, 5.0))
            .unwrap();
        let b = set
            .create(&BodyDef::dynamic(Vec2::new(-1.0, -0.5)).with_mass(1.0, 0.1))
            .unwrap();
        (set, a, b)
    }

    #[test]
    fn defaults_are_box2d_s_and_validate_rejects_bad_values() {
        let (_, a, b) = pair();
        let def = WheelJointDef::new(a, b, Vec2::new(-1.0, -0.5), Vec2::ZERO, Vec2::Y);
        assert!(def.enable_spring);
        assert_eq!((def.hertz, def.damping_ratio), (1.0, 0.7));
        assert_eq!(def.validate(), Ok(()));
        let mut nan = def.clone();
        nan.hertz = Real::NAN;
        assert_eq!(nan.validate(), Err(JointError::NonFinite));
        assert_eq!(
            def.clone().with_motor(1.0, -1.0).validate(),
            Err(JointError::Negative)
        );
        assert_eq!(
            def.clone().with_limits(0.2, 0.1).validate(),
            Err(JointError::InvalidLimits)
        );
    }

    #[test]
    fn the_rows_report_every_row_the_joint_counts() {
        let (mut set, a, b) = pair();
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::new(0.0, -10.0));
        let def = WheelJointDef::new(a, b, Vec2::new(-1.0, -0.3), Vec2::ZERO, Vec2::Y)
            .with_spring(5.0, 0.7)
            .with_motor(-10.0, 100.0)
            .with_limits(-0.3, 0.1);
        let mut joint = WheelJoint::new(def);
        joint.prepare(&ctx, &set);
        joint.solve(&ctx, &mut set.states, true);
        let rows = joint.rows(&ctx, &set);
        assert_eq!(rows.rows.len(), joint.row_count());
    }
}
