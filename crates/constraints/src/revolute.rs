//! The revolute joint: a shared point, with optional angle limits, a motor
//! and an angular spring.
//!
//! # Derivation
//!
//! Bodies `a` and `b` with centres `x_a`, `x_b`, angles `θ_a`, `θ_b`, and
//! anchors `r_a = R(θ_a)(l_a − c_a)`, `r_b = R(θ_b)(l_b − c_b)` measured from
//! the centres of mass.
//!
//! **Point (2 rows).** `C = (x_b + r_b) − (x_a + r_a)`, so
//! `Ċ = v_b + ω_b × r_b − v_a − ω_a × r_a = J v` with
//!
//! ```text
//! J = [ −I  −perp(r_a)   I  perp(r_b) ]
//! K = J M⁻¹ Jᵀ = (m_a⁻¹ + m_b⁻¹) I + i_a⁻¹ perp(r_a) perp(r_a)ᵀ + i_b⁻¹ perp(r_b) perp(r_b)ᵀ
//! ```
//!
//! solved as a 2×2 block: `λ = −s_m K⁻¹ (Ċ + β C) − s_i λ_acc` with the soft
//! coefficients `β, s_m, s_i` of [`Softness`]
//! and the bias `β C` capped at the joint correction speed so that a large
//! initial error recovers gently instead of flinging the bodies.
//!
//! The point rows' spring is built on the heavier body's mass
//! (Softness::with_mass_ratio): `ρ = min((m_a⁻¹ + m_b⁻¹) / min(m_a⁻¹, m_b⁻¹), ρ_max)`,
//! `ρ = ρ_max` against a static or kinematic body, so a light link under a
//! heavy load stretches `ρ` times less; `ρ_max` keeps one Gauss–Seidel
//! iteration per substep stable.
//!
//! **Angle (1 row each).** `C = θ_b − θ_a − θ_ref`, `J = [0 −1 0 1]`,
//! `K = i_a⁻¹ + i_b⁻¹`. The spring drives `C` to zero with its own softness;
//! the motor drives `Ċ` to the target speed with the impulse clamped to
//! `max_motor_torque · h`; the limits are the one-sided rows
//! `C − lower ≥ 0` and `upper − C ≥ 0`, speculative while apart.

use janus2d_core::body::{BodyHandle, BodySet, BodyState};
use janus2d_core::constraint::{Block, Constraint, ConstraintRows, StepContext};
use janus2d_core::math::{Real, Vec2};
use janus2d_core::softness::Softness;

use crate::joint_base::{JointBase, RowsAt};
use crate::joint_def::{JointDefBase, KindDef, LimitsMut, MotorMut, SpringMut};
use crate::joint_rows::{Bounds, PointTerms, RowSolve, Terms, WarmSide, point_bound};
use crate::kind_rows::{KindRows, TreeRows};
use crate::parts::{AnglePart, PairMass, PointPart, angular_correction_cap};
use crate::revolute_lanes::{LaneImpulses, RevoluteLane};
use crate::{JointError, check_motor_speed, check_spring};

/// Everything needed to create a revolute joint.
///
/// ```
/// use janus2d_constraints::{RevoluteJointDef, JointError};
/// use janus2d_core::{BodyDef, BodySet, Vec2};
/// let mut bodies = BodySet::new();
/// let a = bodies.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// let b = bodies.create(&BodyDef::dynamic(Vec2::X)).unwrap();
/// let def = RevoluteJointDef::new(a, b, Vec2::X, Vec2::ZERO)
///     .with_limits(-0.5, 0.5)
///     .with_motor(1.0, 10.0);
/// assert!(def.validate().is_ok());
/// assert_eq!(def.clone().with_limits(1.0, -1.0).validate(), Err(JointError::InvalidLimits));
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RevoluteJointDef {
    /// Bodies, frames (the anchors; the reference angle is `φ_a − φ_b`)
    /// and shared settings.
    pub base: JointDefBase,
    /// Enables the angle limits.
    pub enable_limit: bool,
    /// Lower angle limit, rad.
    pub lower_angle: Real,
    /// Upper angle limit, rad.
    pub upper_angle: Real,
    /// Enables the motor.
    pub enable_motor: bool,
    /// Motor target speed, rad/s.
    pub motor_speed: Real,
    /// Maximum motor torque, N·m (finite, ≥ 0).
    pub max_motor_torque: Real,
    /// Enables the angular spring.
    pub enable_spring: bool,
    /// Spring stiffness, Hz.
    pub hertz: Real,
    /// Spring damping ratio (dimensionless).
    pub damping_ratio: Real,
    /// The joint angle the spring drives toward, rad.
    pub target_angle: Real,
}

impl Default for RevoluteJointDef {
    /// A plain hinge between two placeholder bodies
    /// ([`JointDefBase::default`]: set `base.body_a` and `base.body_b`
    /// before use; `validate` refuses the placeholders as one body).
    fn default() -> Self {
        Self::from_base(JointDefBase::default())
    }
}

impl RevoluteJointDef {
    /// A plain hinge between two bodies at the given local anchors.
    pub fn new(
        body_a: BodyHandle,
        body_b: BodyHandle,
        local_anchor_a: Vec2,
        local_anchor_b: Vec2,
    ) -> Self {
        Self::from_base(JointDefBase::with_anchors(
            body_a,
            body_b,
            local_anchor_a,
            local_anchor_b,
        ))
    }

    /// A plain hinge on a shared base (frames, thresholds, softness).
    pub fn from_base(base: JointDefBase) -> Self {
        RevoluteJointDef {
            base,
            enable_limit: false,
            lower_angle: 0.0,
            upper_angle: 0.0,
            enable_motor: false,
            motor_speed: 0.0,
            max_motor_torque: 0.0,
            enable_spring: false,
            hertz: 0.0,
            damping_ratio: 0.0,
            target_angle: 0.0,
        }
    }

    /// Sets the reference angle `θ_b − θ_a` at which the joint angle is
    /// zero, rad (builder style): frame a's angle, frame b's set to 0.
    pub fn with_reference_angle(mut self, angle: Real) -> Self {
        self.base.local_frame_a.angle = angle;
        self.base.local_frame_b.angle = 0.0;
        self
    }

    /// Lets the two bodies collide (builder style).
    pub fn with_collide_connected(mut self, on: bool) -> Self {
        self.base.collide_connected = on;
        self
    }

    /// Enables limits (builder style).
    pub fn with_limits(mut self, lower: Real, upper: Real) -> Self {
        self.enable_limit = true;
        self.lower_angle = lower;
        self.upper_angle = upper;
        self
    }

    /// Enables the motor (builder style).
    pub fn with_motor(mut self, speed: Real, max_torque: Real) -> Self {
        self.enable_motor = true;
        self.motor_speed = speed;
        self.max_motor_torque = max_torque;
        self
    }

    /// Enables the spring (builder style).
    pub fn with_spring(mut self, hertz: Real, damping_ratio: Real) -> Self {
        self.enable_spring = true;
        self.hertz = hertz;
        self.damping_ratio = damping_ratio;
        self
    }

    /// Sets the joint angle the spring drives toward, rad (builder style).
    pub fn with_target_angle(mut self, angle: Real) -> Self {
        self.target_angle = angle;
        self
    }

    /// Checks the definition's own values (not the handles).
    pub fn validate(&self) -> Result<(), JointError> {
        self.base.validate()?;
        let finite = self.lower_angle.is_finite()
            && self.upper_angle.is_finite()
            && self.motor_speed.is_finite()
            && self.max_motor_torque.is_finite()
            && self.hertz.is_finite()
            && self.damping_ratio.is_finite()
            && self.target_angle.is_finite();
        if !finite {
            return Err(JointError::NonFinite);
        }
        if self.enable_limit && self.lower_angle > self.upper_angle {
            return Err(JointError::InvalidLimits);
        }
        if self.max_motor_torque < 0.0 || self.hertz < 0.0 || self.damping_ratio < 0.0 {
            return Err(JointError::Negative);
        }
        check_motor_speed(self.motor_speed)?;
        check_spring(self.hertz, self.damping_ratio)
    }
}

impl KindDef for RevoluteJointDef {
    fn base(&self) -> &JointDefBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointDefBase {
        &mut self.base
    }
    fn validate(&self) -> Result<(), JointError> {
        RevoluteJointDef::validate(self)
    }
    fn limits_mut(&mut self) -> Option<LimitsMut<'_>> {
        Some(LimitsMut {
            enable: &mut self.enable_limit,
            lower: &mut self.lower_angle,
            upper: &mut self.upper_angle,
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

/// A revolute joint in solver form.
///
/// Laid out in declaration order (`repr(C)`): the fields a Gauss–Seidel
/// point row reads (its base, point part, softness and row switches)
/// first, near each other; the definition is boxed apart and the
/// solve reads it only for the settings of a row that is switched on
/// (the measurement is in docs/performance.md).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(C)]
pub struct RevoluteJoint {
    /// State indices, masses and switches the solver reads.
    pub(crate) base: JointBase,
    pub(crate) point: PointPart,
    /// Softness of the point rows for this step (mass-ratio aware).
    point_softness: Softness,
    /// The definition's row switches (spring, motor, limit), copied at
    /// prepare so that the solve reads no line of the definition.
    switches: Switches,
    /// The angle rows' settings, copied at prepare with the switches
    /// (not in a snapshot: every step's prepare copies them again from the
    /// definition, which is).
    #[cfg_attr(feature = "serde", serde(skip))]
    angles: AngleSettings,
    /// `θ_b − θ_a − θ_ref` at the start of the step, rad.
    delta_angle: Real,
    spring: AnglePart,
    motor: AnglePart,
    lower: AnglePart,
    upper: AnglePart,
    spring_softness: Softness,
    /// The definition it was made from (limits, motor and spring settings).
    pub(crate) def: Box<RevoluteJointDef>,
}

/// The definition's settings the angle rows read in every iteration,
/// copied at prepare: a ragdoll's joint runs all four angle rows, and
/// reading them through the boxed definition cost a dependent load per
/// joint and iteration (the measurement is in docs/performance.md).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct AngleSettings {
    /// The spring's rest angle, rad.
    target_angle: Real,
    /// The motor's target speed, rad/s.
    motor_speed: Real,
    /// The motor's largest torque, N·m.
    max_motor_torque: Real,
    /// The lower limit, rad.
    lower_angle: Real,
    /// The upper limit, rad.
    upper_angle: Real,
}

impl AngleSettings {
    fn of(def: &RevoluteJointDef) -> Self {
        AngleSettings {
            target_angle: def.target_angle,
            motor_speed: def.motor_speed,
            max_motor_torque: def.max_motor_torque,
            lower_angle: def.lower_angle,
            upper_angle: def.upper_angle,
        }
    }
}

/// Which angle rows a revolute joint solves this step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Switches {
    spring: bool,
    motor: bool,
    limit: bool,
}

impl Switches {
    fn of(def: &RevoluteJointDef) -> Self {
        Switches {
            spring: def.enable_spring,
            motor: def.enable_motor,
            limit: def.enable_limit,
        }
    }
}

/// The softness of the Gauss–Seidel point rows: the joint softness scaled
/// by the mass ratio `ρ = min((m_a⁻¹ + m_b⁻¹) / min(m_a⁻¹, m_b⁻¹), ρ_max)`
/// (`ρ_max` when one body is static). Used by the solve and reported by
/// `rows()`, so both see the same rows.
fn point_softness(def: &RevoluteJointDef, ctx: &StepContext, m: &PairMass) -> Softness {
    def.base.rigid_softness(ctx, m.a.inv_mass, m.b.inv_mass)
}

impl RevoluteJoint {
    /// Rows this joint adds to the solver when enabled: two point rows,
    /// two limit rows (lower and upper) when the limit is on, one motor row
    /// and one spring row when those are on.
    #[must_use]
    pub fn row_count(&self) -> usize {
        2 + 2 * usize::from(self.def.enable_limit)
            + usize::from(self.def.enable_motor)
            + usize::from(self.def.enable_spring)
    }

    /// A joint from a definition (validate it first).
    pub fn new(def: RevoluteJointDef) -> Self {
        RevoluteJoint {
            switches: Switches::of(&def),
            angles: AngleSettings::of(&def),
            def: Box::new(def),
            base: JointBase::default(),
            point: PointPart::default(),
            delta_angle: 0.0,
            spring: AnglePart::default(),
            motor: AnglePart::default(),
            lower: AnglePart::default(),
            upper: AnglePart::default(),
            spring_softness: Softness::RIGID,
            point_softness: Softness::RIGID,
        }
    }

    /// Carries the accumulated impulses through a portal when both ends of
    /// the joint move to the other side: the point impulse (world frame)
    /// becomes `scale · rotation · P` (`rotation = Q`, `scale = 1/η`: an
    /// impulse `P` on side 1 moves the object as `Q P / η` does on side 2,
    /// since the portal rows keep `p₁ + η Qᵀ p₂`); the angle rows' impulses
    /// are unchanged (the rows keep `I₁ω₁ + I₂ω₂`, and `r × P` is the same
    /// on both sides).
    pub fn carry_through_portal(&mut self, rotation: janus2d_core::math::Rot, scale: Real) {
        self.point.impulse = scale * rotation.rotate(self.point.impulse);
    }

    /// The world anchors on a and b (their distance is the joint gap).
    pub fn world_anchors(&self, bodies: &BodySet) -> (Vec2, Vec2) {
        self.def.base.world_anchors(bodies)
    }

    /// Distance between the two world anchors, m.
    pub fn gap(&self, bodies: &BodySet) -> Real {
        let (pa, pb) = self.world_anchors(bodies);
        (pb - pa).length()
    }

    /// The joint angle `θ_b − θ_a − θ_ref`, rad.
    pub fn angle(&self, bodies: &BodySet) -> Real {
        crate::joint_base::relative_angle(
            bodies,
            self.def.base.body_a,
            self.def.base.body_b,
            self.def.base.reference_angle(),
        )
    }

    /// True when the last step solved the point rows directly (the joint
    /// is part of a tree of joints, see [`crate::joint_tree`]).
    pub fn in_tree(&self) -> bool {
        self.base.in_tree
    }

    /// False when the joint is disabled (skipped by the solver).
    #[must_use]
    pub fn is_enabled(&self) -> bool {
        self.base.enabled
    }

    /// Point impulse of one substep of the last solved step, N·s (each
    /// substep applies it again: over the step the joint transmits
    /// `substeps` times this; see [`RevoluteJoint::constraint_force`]).
    pub fn linear_impulse(&self) -> Vec2 {
        self.point.impulse
    }

    /// Motor impulse of one substep of the last solved step, N·m·s.
    pub fn motor_impulse(&self) -> Real {
        self.motor.impulse
    }

    /// Force the joint applies to body b over the last solved step, N
    /// (body a gets the opposite). Kept while both bodies sleep. A 10 kg
    /// bob hanging from a pin under g = 10 m/s² reads 100 N upwards.
    #[must_use]
    pub fn constraint_force(&self) -> Vec2 {
        self.point.impulse * self.base.inv_h
    }

    /// Torque about the joint axis that the spring, motor and limits apply
    /// to body b over the last solved step, N·m.
    #[must_use]
    pub fn constraint_torque(&self) -> Real {
        let axial =
            self.spring.impulse + self.motor.impulse + self.lower.impulse - self.upper.impulse;
        axial * self.base.inv_h
    }

    /// True when the spring, the motor or the limits are on: the joint has
    /// angle rows, which the Gauss–Seidel pass solves even in a tree.
    #[inline(always)]
    pub(crate) fn has_angle_rows(&self) -> bool {
        self.def.enable_spring || self.def.enable_motor || self.def.enable_limit
    }

    /// Whether the last prepare switched on an angle row (the switches it
    /// copied; the definition is boxed apart).
    #[inline]
    pub(crate) fn has_prepared_angle_rows(&self) -> bool {
        let on = self.switches;
        on.spring || on.motor || on.limit
    }

    /// What the joint's Gauss–Seidel rows read this step, for a lane
    /// ([`crate::revolute_lanes`]: a solved joint with angle rows, its point
    /// rows too where it is in no tree); `h` is the substep, s.
    pub(crate) fn lane(&self, h: Real) -> RevoluteLane {
        let base = &self.base;
        let on = self.switches;
        let m = &base.masses;
        RevoluteLane {
            state: [base.state_a, base.state_b],
            inv_inertia: [m.a.inv_inertia, m.b.inv_inertia],
            delta_angle: self.delta_angle,
            reads_angle: on.spring || on.limit,
            spring: on.spring && m.a.inv_inertia + m.b.inv_inertia > 0.0,
            spring_softness: self.spring_softness,
            target_angle: self.angles.target_angle,
            motor: on.motor,
            motor_bias: -self.angles.motor_speed,
            motor_max: h * self.angles.max_motor_torque,
            limit: on.limit,
            lower_angle: self.angles.lower_angle,
            upper_angle: self.angles.upper_angle,
            mass: [
                self.spring.mass,
                self.motor.mass,
                self.lower.mass,
                self.upper.mass,
            ],
            impulse: [
                self.spring.impulse,
                self.motor.impulse,
                self.lower.impulse,
                self.upper.impulse,
            ],
            point: !base.in_tree,
            inv_mass: [m.a.inv_mass, m.b.inv_mass],
            frames: [self.point.frame_a, self.point.frame_b],
            delta_center: self.point.delta_center,
            point_softness: self.point_softness,
            point_impulse: self.point.impulse,
        }
    }

    /// Takes back its impulses from a lane: the angle rows' (spring,
    /// motor, lower, upper) and the point's where the lane solved it.
    pub(crate) fn set_lane_impulses(&mut self, impulses: LaneImpulses) {
        let [spring, motor, lower, upper] = impulses.angle;
        self.spring.impulse = spring;
        self.motor.impulse = motor;
        self.lower.impulse = lower;
        self.upper.impulse = upper;
        if let Some(p) = impulses.point {
            self.point.impulse = p;
        }
    }

    #[inline(always)]
    fn current_angle(&self, sa: &BodyState, sb: &BodyState) -> Real {
        janus2d_core::math::wrap_angle(self.delta_angle + sa.dq.relative_angle(sb.dq))
    }
}

impl KindRows for RevoluteJoint {
    fn base(&self) -> &JointBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointBase {
        &mut self.base
    }
    fn row_count(&self) -> usize {
        RevoluteJoint::row_count(self)
    }
    fn is_driven(&self) -> bool {
        self.def.enable_motor && self.def.max_motor_torque > 0.0
    }
    fn constraint_force(&self) -> Vec2 {
        RevoluteJoint::constraint_force(self)
    }
    fn constraint_torque(&self) -> Real {
        RevoluteJoint::constraint_torque(self)
    }
    fn carry_through_portal(&mut self, rotation: janus2d_core::math::Rot, scale: Real) {
        RevoluteJoint::carry_through_portal(self, rotation, scale);
    }
    /// The kept impulses of the joint's rows, one body's share: the angle
    /// rows' sum, then the point at the body's current arm.
    #[inline(always)]
    fn warm_rows(&self, w: &mut WarmSide<'_>) {
        w.hinge(
            self.spring.impulse + self.motor.impulse + self.lower.impulse - self.upper.impulse,
            (self.point.frame_a, self.point.frame_b),
            self.point.impulse,
        );
    }
    /// The joint's rows in Box2D's order: spring, motor, limits, then the
    /// point (unless the tree solves it).
    #[inline(always)]
    fn solve_rows(&mut self, ctx: &StepContext, use_bias: bool, s: &mut RowSolve) {
        // The angle depends on the rotations only, which the rows do not
        // change: one atan2 for the spring and the limits.
        let on = self.switches;
        let angle = if on.spring || on.limit {
            self.current_angle(&s.sa, &s.sb)
        } else {
            0.0
        };
        if on.spring && s.m.a.inv_inertia + s.m.b.inv_inertia > 0.0 {
            // A spring: its feedback is its force, not capped.
            let t = Terms::soft(
                self.spring_softness,
                angle - self.angles.target_angle,
                Real::INFINITY,
            );
            s.angle(
                1.0,
                self.spring.mass,
                t,
                Bounds::Free,
                &mut self.spring.impulse,
            );
        }
        if on.motor {
            let t = Terms::motor(self.angles.motor_speed);
            let bounds = Bounds::symmetric(ctx.h * self.angles.max_motor_torque);
            s.angle(1.0, self.motor.mass, t, bounds, &mut self.motor.impulse);
        }
        if on.limit {
            let soft = ctx.joint_softness;
            let max_bias = angular_correction_cap(ctx.joint_max_correction_speed);
            let lower = Terms::limit(
                angle - self.angles.lower_angle,
                soft,
                ctx.inv_h,
                use_bias,
                max_bias,
            );
            s.angle(
                1.0,
                self.lower.mass,
                lower,
                Bounds::ONE_SIDED,
                &mut self.lower.impulse,
            );
            let upper = Terms::limit(
                self.angles.upper_angle - angle,
                soft,
                ctx.inv_h,
                use_bias,
                max_bias,
            );
            s.angle(
                -1.0,
                self.upper.mass,
                upper,
                Bounds::ONE_SIDED,
                &mut self.upper.impulse,
            );
        }
        if !self.base.in_tree {
            let (r_a, r_b, c) = self.point.arms(&s.sa, &s.sb);
            let t = PointTerms::equality(
                self.point_softness,
                c,
                ctx.joint_max_correction_speed,
                use_bias,
            );
            s.point_equality(r_a, r_b, t, &mut self.point.impulse);
        }
    }
    #[inline(always)]
    fn tree_rows(&self) -> Option<TreeRows<'_>> {
        // A joint with its own constraint softness is solved at it, by
        // the Gauss–Seidel pass.
        (self.def.base.constraint_hertz == 0.0).then_some(TreeRows::Point {
            point: &self.point,
            angle: None,
        })
    }
    #[inline(always)]
    fn set_tree_impulses(&mut self, impulses: [Real; 3]) {
        self.point.impulse = Vec2::new(impulses[0], impulses[1]);
    }
    #[inline(always)]
    fn has_iterative_rows(&self) -> bool {
        !self.base.in_tree || self.has_angle_rows()
    }
    #[cfg(test)]
    fn tree_point_mut(&mut self) -> Option<&mut PointPart> {
        Some(&mut self.point)
    }
}

impl Constraint for RevoluteJoint {
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        let Some((a, b)) = self
            .base
            .load(ctx, bodies, self.def.base.body_a, self.def.base.body_b)
        else {
            return;
        };
        let q_a = a.sim.transform.q;
        let q_b = b.sim.transform.q;
        self.point.frame_a = q_a.rotate(self.def.base.local_frame_a.anchor - a.sim.local_center);
        self.point.frame_b = q_b.rotate(self.def.base.local_frame_b.anchor - b.sim.local_center);
        self.point.delta_center = b.sim.center - a.sim.center;
        self.switches = Switches::of(&self.def);
        self.angles = AngleSettings::of(&self.def);
        // The angle is read by the spring and the limits only (one atan2).
        self.delta_angle = if self.def.enable_spring || self.def.enable_limit {
            janus2d_core::math::wrap_angle(
                q_a.relative_angle(q_b) - self.def.base.reference_angle(),
            )
        } else {
            0.0
        };
        let m = &self.base.masses;
        for part in [
            &mut self.spring,
            &mut self.motor,
            &mut self.lower,
            &mut self.upper,
        ] {
            part.prepare(m);
        }
        self.spring_softness = Softness::new(self.def.hertz, self.def.damping_ratio, ctx.h);
        self.point_softness = point_softness(&self.def, ctx, m);
        if !ctx.warm_starting {
            self.point.impulse = Vec2::ZERO;
            self.spring.impulse = 0.0;
            self.motor.impulse = 0.0;
            self.lower.impulse = 0.0;
            self.upper.impulse = 0.0;
        }
        // The point block's once-a-step bound (`RowSolve::point_equality`).
        self.point.hold_within(point_bound(m, Real::INFINITY));
        if !self.def.enable_spring {
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
        let at = RowsAt::new(bodies, &self.def.base);
        let (m, r_a, r_b, c) = (at.m, at.r_a, at.r_b, at.c);
        // Tree joints' point rows are solved directly, at their own softness.
        let point_softness = if self.base.in_tree {
            ctx.direct_joint_softness
        } else {
            point_softness(&self.def, ctx, &m)
        };
        let mut out = ConstraintRows::default();
        out.rows
            .push(at.point_row(Vec2::X, c.x, point_softness, self.point.impulse.x));
        out.rows
            .push(at.point_row(Vec2::Y, c.y, point_softness, self.point.impulse.y));
        let (k11, k12, k22) = PointPart::effective_mass(&m, r_a, r_b);
        out.blocks.push(Block {
            first_row: 0,
            len: 2,
            k: [[k11, k12, 0.0], [k12, k22, 0.0], [0.0; 3]],
        });
        let angle = self.angle(bodies);
        let k_angle = m.a.inv_inertia + m.b.inv_inertia;
        let mut angle_row =
            |sign: Real, c: Real, softness: Softness, lower: Real, upper: Real, impulse: Real| {
                let first_row = out.rows.len();
                out.rows
                    .push(at.angle_row(sign, c, softness, (lower, upper), impulse));
                out.blocks.push(Block {
                    first_row,
                    len: 1,
                    k: [[k_angle, 0.0, 0.0], [0.0; 3], [0.0; 3]],
                });
            };
        if self.def.enable_spring {
            angle_row(
                1.0,
                angle - self.def.target_angle,
                Softness::new(self.def.hertz, self.def.damping_ratio, ctx.h),
                Real::NEG_INFINITY,
                Real::INFINITY,
                self.spring.impulse,
            );
        }
        if self.def.enable_motor {
            let m = ctx.h * self.def.max_motor_torque;
            angle_row(1.0, 0.0, Softness::RIGID, -m, m, self.motor.impulse);
        }
        if self.def.enable_limit {
            angle_row(
                1.0,
                angle - self.def.lower_angle,
                ctx.joint_softness,
                0.0,
                Real::INFINITY,
                self.lower.impulse,
            );
            angle_row(
                -1.0,
                self.def.upper_angle - angle,
                ctx.joint_softness,
                0.0,
                Real::INFINITY,
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

    /// A joint between bodies of 1 and 100 kg (1 m apart, pinned halfway),
    /// their set and a 60 Hz step's context.
    fn one_to_a_hundred() -> (BodySet, RevoluteJoint, StepContext) {
        let mut set = BodySet::new();
        let a = set
            .create(&BodyDef::dynamic(Vec2::ZERO).with_mass(1.0, 0.1))
            .unwrap();
        let b = set
            .create(&BodyDef::dynamic(Vec2::new(1.0, 0.0)).with_mass(100.0, 10.0))
            .unwrap();
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
        let joint = RevoluteJoint::new(RevoluteJointDef::new(
            a,
            b,
            Vec2::new(0.5, 0.0),
            Vec2::new(-0.5, 0.0),
        ));
        (set, joint, ctx)
    }

    /// The point block's once-a-step bound (`RowSolve::point_equality` no
    /// longer checks it in every iteration): a kept impulse past
    /// `m_eff · ROW_SPEED_BOUND` (bodies of 1 and 100 kg: `m_eff = 100/101
    /// kg`, bound 396,040 N·s) is held at the bound in its own direction at
    /// prepare, and one inside it is kept bit for bit.
    #[test]
    fn a_kept_point_impulse_past_the_row_bound_is_held_at_prepare() {
        let (set, mut joint, ctx) = one_to_a_hundred();
        let bound = crate::parts::ROW_SPEED_BOUND / (1.0 + 0.01);
        joint.point.impulse = Vec2::new(3.0e5, 4.0e5);
        joint.prepare(&ctx, &set);
        let held = joint.point.impulse;
        assert!((held.length() - bound).abs() <= 1e-6 * bound, "{held:?}");
        assert!((held.x / held.y - 0.75).abs() < 1e-6, "{held:?}");
        let inside = Vec2::new(3.0e3, -4.0e3);
        joint.point.impulse = inside;
        joint.prepare(&ctx, &set);
        assert_eq!(joint.point.impulse, inside);
    }

    #[test]
    fn rows_report_the_mass_ratio_softness_the_solve_uses() {
        let (set, mut joint, ctx) = one_to_a_hundred();
        joint.prepare(&ctx, &set);
        assert_ne!(
            joint.point_softness, ctx.joint_softness,
            "a 1:100 pair is softened by its mass ratio"
        );
        let rows = joint.rows(&ctx, &set);
        for row in &rows.rows[..2] {
            assert_eq!(row.softness, joint.point_softness);
        }
    }
}
