//! The prismatic joint: body b slides along an axis fixed in body a, the
//! relative angle locked; optional translation limits, a linear motor and
//! a spring along the axis.
//!
//! # Derivation
//!
//! Bodies `a` and `b` with centres `x_a`, `x_b`, angles `θ_a`, `θ_b`,
//! anchors `r_a = R(θ_a)(l_a − c_a)`, `r_b = R(θ_b)(l_b − c_b)` measured
//! from the centres of mass, and the anchors' separation
//! `d = (x_b + r_b) − (x_a + r_a)`. The axis is frame a's x axis,
//! `n = R(θ_a) R(φ_a) x̂`, turning with body a (`ṅ = ω_a perp(n)`); its
//! normal is `perp = perp(n) = (−n.y, n.x)` (`ṗerp = −ω_a n`).
//!
//! **Perpendicular row.** `C_⊥ = perp · d`. With `ḋ = v_b + ω_b × r_b − v_a
//! − ω_a × r_a`, `perp · (ω × r) = ω (r × perp)` and
//! `ṗerp · d = −ω_a (n · d) = −ω_a (d × perp)`:
//!
//! ```text
//! Ċ_⊥ = perp·(v_b − v_a) + ω_b (r_b × perp) − ω_a ((r_a + d) × perp)
//! J_⊥ = [ −perp  −(r_a + d) × perp │ perp  r_b × perp ]
//! ```
//!
//! **Axial rows** (spring, motor, limits). The translation `t = n · d`;
//! the same steps with `ṅ · d = ω_a (perp · d) = −ω_a (d × n)` give
//! `J_t = [ −n  −(r_a + d) × n │ n  r_b × n ]`. Each axial row is an
//! [`AxisPart`] on this [`AxisRow`] (`s_a = (r_a + d) × n`, `s_b = r_b × n`,
//! `K = m_a⁻¹ + m_b⁻¹ + i_a s_a² + i_b s_b²`): the spring drives
//! `t − target_translation` to zero with its own softness, the motor drives
//! `ṫ` to `motor_speed` with the impulse clamped to `max_motor_force · h`,
//! and the limits are the one-sided rows `t − lower ≥ 0` and
//! `upper − t ≥ 0` (the upper one along `−J_t`), speculative while apart
//! as the revolute joint's angle limits, at the softness of the rigid
//! linear rows.
//!
//! **Angle row.** `C_θ = θ_b − θ_a − θ_ref`, `J_θ = [ 0 −1 │ 0 1 ]`.
//!
//! **The perpendicular and angle rows together.** With
//! `s_a = (r_a + d) × perp`, `s_b = r_b × perp`, `i = I⁻¹`:
//!
//! ```text
//! K = [ m_a⁻¹ + m_b⁻¹ + i_a s_a² + i_b s_b²    i_a s_a + i_b s_b ]
//!     [ i_a s_a + i_b s_b                      i_a + i_b         ]
//! ```
//!
//! The two rows are solved together as this 2×2 block: `K₁₂` is large
//! whenever the anchors sit off the line through the centres (a load on a
//! platform, a slider carrying a long arm), and a sequential solve then
//! trades perpendicular error for angle error from one row to the next,
//! converging slowly in one iteration per substep; the block satisfies
//! both at once each iteration (as Box2D v3 does). `Δλ_i = −s_m,i
//! [K⁻¹ (Ċ + b)]_i − s_i,i λ_i` with each row's own soft coefficients:
//! both are rigid through [`JointDefBase::rigid_softness`], on the inverse
//! masses for the perpendicular row and on the inverse inertias for the
//! angle row (the same bias rate; the mass ratio stiffens each on its own
//! scale). The perpendicular bias is capped at the joint correction speed
//! as the point rows' are. When neither body turns (`i_a + i_b = 0`) or
//! neither moves linearly the block is singular and the two rows are
//! solved one after the other.
//!
//! **Order.** One iteration solves the spring, the motor, the rigid block,
//! then the limits (Box2D v3 solves the limits before the block). A limit
//! row's angular entry on body a is `(r_a + d) × n`, which grows with the
//! anchors' separation `d`: solved before the block, a violated limit far
//! down the rail corrected mostly by turning body a, the block's angle row
//! took the turn back, and the two fought, their kept impulses growing
//! step after step (a slider created 24 m beyond its limits on a rail at
//! 2.5 rad reached 400 m/s and wandered 260 m away). Solved after the
//! block, the limit has the last word in the iteration and the block
//! takes the turn back at the next: the same slider returns within its
//! limits below the correction speed. (A joint in the tree has its block
//! solved by the tree, after this pass.)
//!
//! **Warm start geometry.** The warm start is applied one body at a time
//! (the colour stage's per-body share), and a body's share here depends on
//! both bodies' positions (`n`, `d`). So the joint keeps the rows of its
//! last iteration: the relax iteration runs after the positions are
//! integrated, so the kept rows are those of the current positions when
//! the next substep warm-starts (prepare sets them for the first).

use janus2d_core::body::{BodyHandle, BodySet, BodyState, SolverBody};
use janus2d_core::constraint::{Block, Constraint, ConstraintRows, StepContext};
use janus2d_core::math::{Real, Rot, Vec2, cross};
use janus2d_core::softness::Softness;

use crate::joint_base::{JointBase, RowsAt};
use crate::joint_def::{JointDefBase, JointFrame, KindDef, LimitsMut, MotorMut, SpringMut};
use crate::joint_rows::{Bounds, RowSolve, Terms, WarmSide};
use crate::kind_rows::{GeneralRows, KindRows, TreeRows};
use crate::parts::{AxisPart, AxisRow, PairMass, angular_correction_cap};
use crate::{JointError, check_spring};

/// Checks a linear motor speed against
/// [`MAX_SPEED`](janus2d_core::limits::MAX_SPEED), m/s.
pub(crate) fn check_linear_motor_speed(speed: Real) -> Result<(), JointError> {
    let max = janus2d_core::limits::MAX_SPEED;
    if speed.abs() > max {
        return Err(JointError::OutOfBounds {
            field: "motor_speed",
            min: -max,
            max,
        });
    }
    Ok(())
}

/// Checks a translation (a limit, a spring target) against
/// [`MAX_EXTENT`](janus2d_core::limits::MAX_EXTENT), m.
pub(crate) fn check_translation(x: Real, field: &'static str) -> Result<(), JointError> {
    let max = janus2d_core::limits::MAX_EXTENT;
    if x.abs() > max {
        return Err(JointError::OutOfBounds {
            field,
            min: -max,
            max,
        });
    }
    Ok(())
}

/// The frames of a joint along an axis fixed in body a, from the axis
/// given in a's frame (any length but zero): frame a turned to the axis,
/// frame b at the same angle (reference angle 0).
fn axis_frames(
    local_anchor_a: Vec2,
    local_anchor_b: Vec2,
    local_axis_a: Vec2,
) -> (JointFrame, JointFrame) {
    let angle = if local_axis_a == Vec2::ZERO {
        0.0
    } else {
        local_axis_a.y.atan2(local_axis_a.x)
    };
    (
        JointFrame::new(local_anchor_a, angle),
        JointFrame::new(local_anchor_b, angle),
    )
}

/// The geometry a joint along an axis of body a (prismatic, wheel) keeps
/// for a step: the anchors' arms, the centres' offset and the axis at the
/// start of the step, from which each iteration rebuilds its rows with
/// the states' deltas.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct SlideFrame {
    /// Anchor on a from a's centre (world frame), m.
    frame_a: Vec2,
    /// Anchor on b from b's centre (world frame), m.
    frame_b: Vec2,
    /// `c_b − c_a`, m.
    delta_center: Vec2,
    /// Frame a's x axis (world frame, unit).
    axis: Vec2,
}

/// An axis joint's rows at the current substep.
pub(crate) struct SlideRows {
    /// The perpendicular row `J_⊥`.
    pub(crate) perp: AxisRow,
    /// The axial row `J_t`.
    pub(crate) axial: AxisRow,
    /// `C_⊥ = perp · d`, m.
    pub(crate) c_perp: Real,
    /// `t = n · d`, m.
    pub(crate) translation: Real,
}

/// The rows along `n` and `perp(n)` for arms `r_a`, `r_b` and separation
/// `d` (module docs).
fn slide_rows(m: &PairMass, n: Vec2, r_a: Vec2, r_b: Vec2, d: Vec2) -> SlideRows {
    let p = n.perp();
    let arm_a = r_a + d;
    SlideRows {
        perp: AxisRow::new(m, p, cross(arm_a, p), cross(r_b, p)),
        axial: AxisRow::new(m, n, cross(arm_a, n), cross(r_b, n)),
        c_perp: p.dot(d),
        translation: n.dot(d),
    }
}

impl SlideFrame {
    /// The geometry at the start of a step.
    pub(crate) fn prepare(def: &JointDefBase, a: &SolverBody<'_>, b: &SolverBody<'_>) -> Self {
        let q_a = a.sim.transform.q;
        let q_b = b.sim.transform.q;
        SlideFrame {
            frame_a: q_a.rotate(def.local_frame_a.anchor - a.sim.local_center),
            frame_b: q_b.rotate(def.local_frame_b.anchor - b.sim.local_center),
            delta_center: b.sim.center - a.sim.center,
            axis: q_a.rotate(def.local_frame_a.axis()),
        }
    }

    /// The rows at the states' current positions.
    #[inline(always)]
    pub(crate) fn rows(&self, sa: &BodyState, sb: &BodyState, m: &PairMass) -> SlideRows {
        let r_a = sa.dq.rotate(self.frame_a);
        let r_b = sb.dq.rotate(self.frame_b);
        let d = (sb.dp - sa.dp) + (r_b - r_a) + self.delta_center;
        slide_rows(m, sa.dq.rotate(self.axis), r_a, r_b, d)
    }
}

/// An axis joint's geometry at the bodies' current poses, for `rows()`
/// and read-backs: the rows, the arms' geometry and frame a's axis.
pub(crate) fn slide_rows_at(bodies: &BodySet, def: &JointDefBase) -> (RowsAt, SlideRows) {
    let at = RowsAt::new(bodies, def);
    let q_a = bodies.solver_body(def.body_a).sim.transform.q;
    let n = q_a.rotate(def.local_frame_a.axis());
    let rows = slide_rows(&at.m, n, at.r_a, at.r_b, at.c);
    (at, rows)
}

/// `Ċ = J v` of an [`AxisRow`] at the bodies' current velocities.
pub(crate) fn row_speed(bodies: &BodySet, def: &JointDefBase, row: &AxisRow) -> Real {
    let state = |h| bodies.state(h).copied().unwrap_or(BodyState::IDENTITY);
    row.c_dot(&state(def.body_a), &state(def.body_b))
}

/// Everything needed to create a prismatic joint.
///
/// ```
/// use janus2d_constraints::{JointError, PrismaticJointDef};
/// use janus2d_core::{BodyDef, BodySet, Vec2};
/// let mut bodies = BodySet::new();
/// let ground = bodies.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// let platform = bodies.create(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
/// // A vertical slide through the platform's centre, 0..3 m, driven up
/// // at 1 m/s by up to 2 kN.
/// let def = PrismaticJointDef::at_world(&bodies, ground, platform, Vec2::new(0.0, 1.0), Vec2::Y)
///     .unwrap()
///     .with_limits(0.0, 3.0)
///     .with_motor(1.0, 2000.0);
/// assert!(def.validate().is_ok());
/// assert_eq!(def.clone().with_limits(1.0, -1.0).validate(), Err(JointError::InvalidLimits));
/// assert_eq!(def.with_motor(1.0, -5.0).validate(), Err(JointError::Negative));
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PrismaticJointDef {
    /// Bodies, frames (the anchors; frame a's x axis is the slide axis; the
    /// held angle `θ_b − θ_a` is `φ_a − φ_b`) and shared settings.
    pub base: JointDefBase,
    /// Enables the translation limits.
    pub enable_limit: bool,
    /// Lower translation limit, m.
    pub lower_translation: Real,
    /// Upper translation limit, m.
    pub upper_translation: Real,
    /// Enables the motor.
    pub enable_motor: bool,
    /// Motor target speed along the axis, m/s.
    pub motor_speed: Real,
    /// Maximum motor force, N (finite, ≥ 0).
    pub max_motor_force: Real,
    /// Enables the spring along the axis.
    pub enable_spring: bool,
    /// Spring stiffness, Hz (0: no spring force).
    pub hertz: Real,
    /// Spring damping ratio (dimensionless).
    pub damping_ratio: Real,
    /// The translation the spring drives toward, m.
    pub target_translation: Real,
}

impl Default for PrismaticJointDef {
    /// A plain slide along frame a's x axis between two placeholder bodies
    /// ([`JointDefBase::default`]: set `base.body_a` and `base.body_b`
    /// before use; `validate` refuses the placeholders as one body).
    fn default() -> Self {
        Self::from_base(JointDefBase::default())
    }
}

impl PrismaticJointDef {
    /// A plain slide between two bodies at the given local anchors along
    /// `local_axis_a` (in a's frame, any nonzero length; zero is the x
    /// axis), holding the relative angle the bodies have at zero.
    pub fn new(
        body_a: BodyHandle,
        body_b: BodyHandle,
        local_anchor_a: Vec2,
        local_anchor_b: Vec2,
        local_axis_a: Vec2,
    ) -> Self {
        let (fa, fb) = axis_frames(local_anchor_a, local_anchor_b, local_axis_a);
        Self::from_base(JointDefBase::with_frames(body_a, body_b, fa, fb))
    }

    /// A plain slide through a world point along a world axis (any
    /// nonzero length), holding the bodies' current relative angle.
    /// `Err(ZeroLength)` for a zero axis, `Err(NonFinite)`,
    /// `Err(UnknownBody)`.
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

    /// A plain slide on a shared base (frames, thresholds, softness).
    pub fn from_base(base: JointDefBase) -> Self {
        PrismaticJointDef {
            base,
            enable_limit: false,
            lower_translation: 0.0,
            upper_translation: 0.0,
            enable_motor: false,
            motor_speed: 0.0,
            max_motor_force: 0.0,
            enable_spring: false,
            hertz: 0.0,
            damping_ratio: 0.0,
            target_translation: 0.0,
        }
    }

    /// Sets the held angle `θ_b − θ_a`, rad (builder style): frame b's
    /// angle becomes `φ_a − angle`, frame a (the axis) is kept.
    pub fn with_reference_angle(mut self, angle: Real) -> Self {
        self.base.local_frame_b.angle = self.base.local_frame_a.angle - angle;
        self
    }

    /// Lets the two bodies collide (builder style).
    pub fn with_collide_connected(mut self, on: bool) -> Self {
        self.base.collide_connected = on;
        self
    }

    /// Enables the translation limits, m (builder style).
    pub fn with_limits(mut self, lower: Real, upper: Real) -> Self {
        self.enable_limit = true;
        self.lower_translation = lower;
        self.upper_translation = upper;
        self
    }

    /// Enables the motor: speed m/s, largest force N (builder style).
    pub fn with_motor(mut self, speed: Real, max_force: Real) -> Self {
        self.enable_motor = true;
        self.motor_speed = speed;
        self.max_motor_force = max_force;
        self
    }

    /// Enables the spring: stiffness Hz, damping ratio (builder style).
    pub fn with_spring(mut self, hertz: Real, damping_ratio: Real) -> Self {
        self.enable_spring = true;
        self.hertz = hertz;
        self.damping_ratio = damping_ratio;
        self
    }

    /// Sets the translation the spring drives toward, m (builder style).
    pub fn with_target_translation(mut self, translation: Real) -> Self {
        self.target_translation = translation;
        self
    }

    /// Checks the definition's own values (not the handles): the base,
    /// finite values, `lower ≤ upper` when the limits are on, non-negative
    /// force, stiffness and damping, translations within
    /// [`MAX_EXTENT`](janus2d_core::limits::MAX_EXTENT) and the speed
    /// within [`MAX_SPEED`](janus2d_core::limits::MAX_SPEED).
    pub fn validate(&self) -> Result<(), JointError> {
        self.base.validate()?;
        let finite = self.lower_translation.is_finite()
            && self.upper_translation.is_finite()
            && self.motor_speed.is_finite()
            && self.max_motor_force.is_finite()
            && self.hertz.is_finite()
            && self.damping_ratio.is_finite()
            && self.target_translation.is_finite();
        if !finite {
            return Err(JointError::NonFinite);
        }
        if self.enable_limit && self.lower_translation > self.upper_translation {
            return Err(JointError::InvalidLimits);
        }
        if self.max_motor_force < 0.0 || self.hertz < 0.0 || self.damping_ratio < 0.0 {
            return Err(JointError::Negative);
        }
        check_translation(self.lower_translation, "lower_translation")?;
        check_translation(self.upper_translation, "upper_translation")?;
        check_translation(self.target_translation, "target_translation")?;
        check_linear_motor_speed(self.motor_speed)?;
        check_spring(self.hertz, self.damping_ratio)
    }
}

impl KindDef for PrismaticJointDef {
    fn base(&self) -> &JointDefBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointDefBase {
        &mut self.base
    }
    fn validate(&self) -> Result<(), JointError> {
        PrismaticJointDef::validate(self)
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
            max: &mut self.max_motor_force,
            linear: true,
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

/// A prismatic joint in solver form.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(C)]
pub struct PrismaticJoint {
    /// State indices, masses and switches the solver reads.
    pub(crate) base: JointBase,
    /// The definition it was made from (limits, motor and spring settings).
    pub(crate) def: Box<PrismaticJointDef>,
    /// The geometry at the start of the step.
    frame: SlideFrame,
    /// `θ_b − θ_a − θ_ref` at the start of the step, rad.
    delta_angle: Real,
    /// The perpendicular row of the last iteration (the warm start's).
    perp_row: AxisRow,
    /// The axial row of the last iteration (the warm start's).
    axial_row: AxisRow,
    /// Accumulated perpendicular impulse, N·s.
    perp_impulse: Real,
    /// Accumulated angle impulse, N·m·s.
    angle_impulse: Real,
    spring: AxisPart,
    motor: AxisPart,
    lower: AxisPart,
    upper: AxisPart,
    /// Softness of the perpendicular row (and the limits) this step.
    linear_softness: Softness,
    /// Softness of the angle row this step.
    angular_softness: Softness,
    /// Softness of the spring this step.
    spring_softness: Softness,
}

/// The rigid rows' softness for a step: linear (perpendicular row,
/// limits) and angular (angle row).
fn softnesses(def: &JointDefBase, ctx: &StepContext, m: &PairMass) -> (Softness, Softness) {
    (
        def.rigid_softness(ctx, m.a.inv_mass, m.b.inv_mass),
        def.rigid_softness(ctx, m.a.inv_inertia, m.b.inv_inertia),
    )
}

/// The perpendicular and angle rows form a regular block: a body turns
/// (`i_a + i_b > 0`, else the angle row is empty) and one moves linearly
/// (`m_a⁻¹ + m_b⁻¹ > 0`, so `det K ≥ (m_a⁻¹ + m_b⁻¹)(i_a + i_b) > 0`).
fn block_is_regular(m: &PairMass) -> bool {
    m.a.inv_inertia + m.b.inv_inertia > 0.0 && m.a.inv_mass + m.b.inv_mass > 0.0
}

impl PrismaticJoint {
    /// A joint from a definition (validate it first).
    pub fn new(def: PrismaticJointDef) -> Self {
        PrismaticJoint {
            def: Box::new(def),
            base: JointBase::default(),
            frame: SlideFrame::default(),
            delta_angle: 0.0,
            perp_row: AxisRow::default(),
            axial_row: AxisRow::default(),
            perp_impulse: 0.0,
            angle_impulse: 0.0,
            spring: AxisPart::default(),
            motor: AxisPart::default(),
            lower: AxisPart::default(),
            upper: AxisPart::default(),
            linear_softness: Softness::RIGID,
            angular_softness: Softness::RIGID,
            spring_softness: Softness::RIGID,
        }
    }

    /// Rows this joint adds to the solver when enabled: the perpendicular
    /// and angle rows, two limit rows when the limits are on, one motor
    /// row and one spring row when those are on.
    #[must_use]
    pub fn row_count(&self) -> usize {
        2 + 2 * usize::from(self.def.enable_limit)
            + usize::from(self.def.enable_motor)
            + usize::from(self.def.enable_spring)
    }

    /// Carries the accumulated impulses through a portal when both ends
    /// move to the other side: the linear rows' impulses (perpendicular,
    /// spring, motor, limits) scale by `scale = 1/η` (their directions
    /// turn with body a's clone, so `rotation` is already in them); the
    /// angle impulse is kept (see [`crate::RevoluteJoint::carry_through_portal`]);
    /// the limits, the spring's target and the motor speed scale by `η`,
    /// as translations along the axis do.
    pub fn carry_through_portal(&mut self, _rotation: Rot, scale: Real) {
        // The anchors scale by η about each copy's centre of mass, so
        // translations along the axis do the same.
        let eta = 1.0 / scale;
        let def = &mut self.def;
        def.lower_translation *= eta;
        def.upper_translation *= eta;
        def.target_translation *= eta;
        def.motor_speed *= eta;
        self.perp_impulse *= scale;
        for part in [
            &mut self.spring,
            &mut self.motor,
            &mut self.lower,
            &mut self.upper,
        ] {
            part.impulse *= scale;
        }
    }

    /// The translation `t = n · d` of b's anchor from a's along the axis
    /// at the bodies' current poses, m.
    #[must_use]
    pub fn translation(&self, bodies: &BodySet) -> Real {
        slide_rows_at(bodies, &self.def.base).1.translation
    }

    /// The perpendicular error `C_⊥ = perp · d` at the bodies' current
    /// poses, m (0 when b's anchor is on the axis).
    #[must_use]
    pub fn perpendicular_error(&self, bodies: &BodySet) -> Real {
        slide_rows_at(bodies, &self.def.base).1.c_perp
    }

    /// The translation speed `ṫ` at the bodies' current velocities, m/s.
    #[must_use]
    pub fn translation_speed(&self, bodies: &BodySet) -> Real {
        let (_, rows) = slide_rows_at(bodies, &self.def.base);
        row_speed(bodies, &self.def.base, &rows.axial)
    }

    /// The angle error `θ_b − θ_a − θ_ref`, rad (wrapped to `[−π, π]`).
    #[must_use]
    pub fn angle(&self, bodies: &BodySet) -> Real {
        crate::joint_base::relative_angle(
            bodies,
            self.def.base.body_a,
            self.def.base.body_b,
            self.def.base.reference_angle(),
        )
    }

    /// False when the joint is disabled (skipped by the solver).
    #[must_use]
    pub fn is_enabled(&self) -> bool {
        self.base.enabled
    }

    /// The axial impulse of one substep of the last solved step (spring,
    /// motor and limits, along `n`), N·s.
    #[must_use]
    pub fn axial_impulse(&self) -> Real {
        self.spring.impulse + self.motor.impulse + self.lower.impulse - self.upper.impulse
    }

    /// The perpendicular impulse of one substep of the last solved step,
    /// N·s.
    #[must_use]
    pub fn perpendicular_impulse(&self) -> Real {
        self.perp_impulse
    }

    /// The angle impulse of one substep of the last solved step, N·m·s.
    #[must_use]
    pub fn angular_impulse(&self) -> Real {
        self.angle_impulse
    }

    /// The motor's force along the axis over the last solved step, N.
    #[must_use]
    pub fn motor_force(&self) -> Real {
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

    /// Torque the angle row applies to body b over the last solved step,
    /// N·m (body a gets the opposite).
    #[must_use]
    pub fn constraint_torque(&self) -> Real {
        self.angle_impulse * self.base.inv_h
    }
}

impl KindRows for PrismaticJoint {
    fn base(&self) -> &JointBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointBase {
        &mut self.base
    }
    fn row_count(&self) -> usize {
        PrismaticJoint::row_count(self)
    }
    fn is_driven(&self) -> bool {
        self.def.enable_motor && self.def.max_motor_force > 0.0
    }
    fn constraint_force(&self) -> Vec2 {
        PrismaticJoint::constraint_force(self)
    }
    fn constraint_torque(&self) -> Real {
        PrismaticJoint::constraint_torque(self)
    }
    fn carry_through_portal(&mut self, rotation: Rot, scale: Real) {
        PrismaticJoint::carry_through_portal(self, rotation, scale);
    }
    /// The kept impulses along the rows of the last iteration (module
    /// docs, "Warm start geometry"): the axial rows' sum, the
    /// perpendicular row's, then the angle row's.
    #[inline(always)]
    fn warm_rows(&self, w: &mut WarmSide<'_>) {
        w.linear(&self.axial_row, self.axial_impulse());
        w.linear(&self.perp_row, self.perp_impulse);
        w.angle(self.angle_impulse);
    }
    /// Spring, motor, the rigid block (unless the tree solves it), then
    /// the limits (module docs, "Order").
    #[inline(always)]
    fn solve_rows(&mut self, ctx: &StepContext, use_bias: bool, s: &mut RowSolve) {
        let rows = self.frame.rows(&s.sa, &s.sb, &s.m);
        let axial = rows.axial;
        let t = rows.translation;
        let cap = ctx.joint_max_correction_speed;
        // The axial rows' impulses are clamped (not summed) even where free.
        let free = Bounds::Clamp(Real::NEG_INFINITY, Real::INFINITY);
        if self.def.enable_spring && self.def.hertz > 0.0 {
            let c = t - self.def.target_translation;
            let terms = Terms::soft(self.spring_softness, c, Real::INFINITY);
            s.linear(&axial, terms, free, &mut self.spring.impulse);
        }
        if self.def.enable_motor {
            let bounds = Bounds::symmetric(ctx.h * self.def.max_motor_force);
            let terms = Terms::motor(self.def.motor_speed);
            s.linear(&axial, terms, bounds, &mut self.motor.impulse);
        }
        if !self.base.in_tree {
            let c_angle =
                janus2d_core::math::wrap_angle(self.delta_angle + s.sa.dq.relative_angle(s.sb.dq));
            let t_perp = Terms::equality(self.linear_softness, rows.c_perp, cap, use_bias);
            let t_angle = Terms::equality(
                self.angular_softness,
                c_angle,
                angular_correction_cap(cap),
                use_bias,
            );
            let k_angle = s.m.a.inv_inertia + s.m.b.inv_inertia;
            if block_is_regular(&s.m) {
                s.linear_angle(
                    &rows.perp,
                    (t_perp, t_angle),
                    (&mut self.perp_impulse, &mut self.angle_impulse),
                );
            } else {
                // One of the block's rows is empty: the two rows apart.
                if k_angle > 0.0 {
                    s.angle(
                        1.0,
                        1.0 / k_angle,
                        t_angle,
                        Bounds::Free,
                        &mut self.angle_impulse,
                    );
                }
                s.linear(&rows.perp, t_perp, Bounds::Free, &mut self.perp_impulse);
            }
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
        self.perp_row = rows.perp;
        self.axial_row = axial;
    }
    /// The perpendicular and angle rows join the exact tree solve (rigid
    /// unless the joint has its own constraint softness); its axial rows
    /// stay iterative, so it always has a Gauss–Seidel pass (which also
    /// keeps the warm start's rows current).
    #[inline(always)]
    fn tree_rows(&self) -> Option<TreeRows<'_>> {
        (self.def.base.constraint_hertz == 0.0).then_some(TreeRows::General { count: 2 })
    }
    #[inline(always)]
    fn tree_general_rows(&self, sa: &BodyState, sb: &BodyState) -> GeneralRows {
        let rows = self.frame.rows(sa, sb, &self.base.masses);
        let p = rows.perp;
        let c_angle =
            janus2d_core::math::wrap_angle(self.delta_angle + sa.dq.relative_angle(sb.dq));
        GeneralRows {
            count: 2,
            j_a: [[-p.n.x, -p.n.y, -p.s_a], [0.0, 0.0, -1.0], [0.0; 3]],
            j_b: [[p.n.x, p.n.y, p.s_b], [0.0, 0.0, 1.0], [0.0; 3]],
            c: [rows.c_perp, c_angle, 0.0],
            linear: [true, false, false],
            impulse: [self.perp_impulse, self.angle_impulse, 0.0],
        }
    }
    #[inline(always)]
    fn set_tree_impulses(&mut self, impulses: [Real; 3]) {
        self.perp_impulse = impulses[0];
        self.angle_impulse = impulses[1];
    }
    #[inline(always)]
    fn has_iterative_rows(&self) -> bool {
        true
    }
}

impl Constraint for PrismaticJoint {
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        let Some((a, b)) = self
            .base
            .load(ctx, bodies, self.def.base.body_a, self.def.base.body_b)
        else {
            return;
        };
        self.frame = SlideFrame::prepare(&self.def.base, &a, &b);
        self.delta_angle = janus2d_core::math::wrap_angle(
            a.sim.transform.q.relative_angle(b.sim.transform.q) - self.def.base.reference_angle(),
        );
        let m = self.base.masses;
        let rows = self
            .frame
            .rows(&BodyState::IDENTITY, &BodyState::IDENTITY, &m);
        self.perp_row = rows.perp;
        self.axial_row = rows.axial;
        (self.linear_softness, self.angular_softness) = softnesses(&self.def.base, ctx, &m);
        self.spring_softness = Softness::new(self.def.hertz, self.def.damping_ratio, ctx.h);
        if !ctx.warm_starting {
            self.perp_impulse = 0.0;
            self.angle_impulse = 0.0;
            self.spring.impulse = 0.0;
            self.motor.impulse = 0.0;
            self.lower.impulse = 0.0;
            self.upper.impulse = 0.0;
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
        let (at, rows) = slide_rows_at(bodies, &self.def.base);
        let m = at.m;
        let (linear, angular) = softnesses(&self.def.base, ctx, &m);
        let free = (Real::NEG_INFINITY, Real::INFINITY);
        let perp = &rows.perp;
        let mut out = ConstraintRows::default();
        out.rows.push(at.axis_row(
            perp.n,
            (perp.s_a, perp.s_b),
            rows.c_perp,
            linear,
            free,
            self.perp_impulse,
        ));
        out.rows
            .push(at.angle_row(1.0, self.angle(bodies), angular, free, self.angle_impulse));
        let (i_a, i_b) = (m.a.inv_inertia, m.b.inv_inertia);
        let k11 =
            m.a.inv_mass + m.b.inv_mass + i_a * perp.s_a * perp.s_a + i_b * perp.s_b * perp.s_b;
        let k12 = i_a * perp.s_a + i_b * perp.s_b;
        let k22 = i_a + i_b;
        if block_is_regular(&m) {
            out.blocks.push(Block {
                first_row: 0,
                len: 2,
                k: [[k11, k12, 0.0], [k12, k22, 0.0], [0.0; 3]],
            });
        } else {
            for (first_row, k) in [(0, k11), (1, k22)] {
                out.blocks.push(Block {
                    first_row,
                    len: 1,
                    k: [[k, 0.0, 0.0], [0.0; 3], [0.0; 3]],
                });
            }
        }
        let axial = &rows.axial;
        let k_axial =
            m.a.inv_mass + m.b.inv_mass + i_a * axial.s_a * axial.s_a + i_b * axial.s_b * axial.s_b;
        let t = rows.translation;
        let mut axial_row =
            |sign: Real, c: Real, softness: Softness, bounds: (Real, Real), impulse: Real| {
                let first_row = out.rows.len();
                out.rows.push(at.axis_row(
                    sign * axial.n,
                    (sign * axial.s_a, sign * axial.s_b),
                    c,
                    softness,
                    bounds,
                    impulse,
                ));
                out.blocks.push(Block {
                    first_row,
                    len: 1,
                    k: [[k_axial, 0.0, 0.0], [0.0; 3], [0.0; 3]],
                });
            };
        if self.def.enable_spring {
            axial_row(
                1.0,
                t - self.def.target_translation,
                Softness::new(self.def.hertz, self.def.damping_ratio, ctx.h),
                free,
                self.spring.impulse,
            );
        }
        if self.def.enable_motor {
            let max = ctx.h * self.def.max_motor_force;
            axial_row(1.0, 0.0, Softness::RIGID, (-max, max), self.motor.impulse);
        }
        if self.def.enable_limit {
            let up = (0.0, Real::INFINITY);
            axial_row(
                1.0,
                t - self.def.lower_translation,
                linear,
                up,
                self.lower.impulse,
            );
            axial_row(
                -1.0,
                self.def.upper_translation - t,
                linear,
                up,
                self.upper.impulse,
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
            .create(&BodyDef::dynamic(Vec2::ZERO).with_mass(2.0, 0.5))
            .unwrap();
        let b = set
            .create(&BodyDef::dynamic(Vec2::new(1.0, 0.3)).with_mass(1.0, 0.2))
            .unwrap();
        (set, a, b)
    }

    #[test]
    fn a_portal_scales_the_translations_by_eta() {
        let (_, a, b) = pair();
        let def = PrismaticJointDef::new(a, b, Vec2::ZERO, Vec2::ZERO, Vec2::X)
            .with_limits(-1.0, 2.0)
            .with_motor(0.5, 10.0)
            .with_spring(2.0, 0.5)
            .with_target_translation(0.75);
        let mut joint = PrismaticJoint::new(def);
        // η = 0.5: the portal's `scale` is 1/η = 2.
        joint.carry_through_portal(Rot::IDENTITY, 2.0);
        let d = &joint.def;
        assert_eq!((d.lower_translation, d.upper_translation), (-0.5, 1.0));
        assert_eq!((d.target_translation, d.motor_speed), (0.375, 0.25));
        assert_eq!(d.max_motor_force, 10.0, "forces are left as set");
    }

    #[test]
    fn validate_rejects_bad_values() {
        let (_, a, b) = pair();
        let def = PrismaticJointDef::new(a, b, Vec2::ZERO, Vec2::ZERO, Vec2::X);
        assert_eq!(def.validate(), Ok(()));
        let mut nan = def.clone();
        nan.motor_speed = Real::NAN;
        assert_eq!(nan.validate(), Err(JointError::NonFinite));
        assert_eq!(
            def.clone().with_limits(1.0, 0.0).validate(),
            Err(JointError::InvalidLimits)
        );
        assert_eq!(
            def.clone().with_motor(1.0, -1.0).validate(),
            Err(JointError::Negative)
        );
        assert_eq!(
            def.clone().with_spring(-1.0, 0.0).validate(),
            Err(JointError::Negative)
        );
        assert!(matches!(
            def.clone().with_motor(1e12, 1.0).validate(),
            Err(JointError::OutOfBounds { .. })
        ));
        assert!(matches!(
            def.clone().with_limits(-1e12, 0.0).validate(),
            Err(JointError::OutOfBounds { .. })
        ));
    }

    #[test]
    fn rows_report_the_block_and_the_solve_softness() {
        let (set, a, b) = pair();
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
        let def = PrismaticJointDef::new(a, b, Vec2::new(0.5, 0.0), Vec2::ZERO, Vec2::X)
            .with_limits(-1.0, 1.0)
            .with_motor(1.0, 10.0)
            .with_spring(2.0, 0.5);
        let mut joint = PrismaticJoint::new(def);
        joint.prepare(&ctx, &set);
        let rows = joint.rows(&ctx, &set);
        assert_eq!(rows.rows.len(), joint.row_count());
        assert_eq!(rows.rows[0].softness, joint.linear_softness);
        assert_eq!(rows.rows[1].softness, joint.angular_softness);
        let lens: Vec<usize> = rows.blocks.iter().map(|b| b.len).collect();
        assert_eq!(lens, vec![2, 1, 1, 1, 1]);
        // The prepare's rows are the report's at the same poses.
        assert!((joint.perp_row.s_a - rows.rows[0].jacobian[0].angular.abs()).abs() < 1e-5);
    }
}
