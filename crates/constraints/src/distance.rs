//! The distance joint: two anchors kept at a length (rigidly, or by a
//! spring), between a minimum and a maximum length, with a motor along
//! the line. A rope is a distance joint with only its maximum.
//!
//! # Derivation
//!
//! Bodies `a` and `b` with centres `x_a`, `x_b`, angles `θ_a`, `θ_b`, and
//! anchors `r_a = R(θ_a)(l_a − c_a)`, `r_b = R(θ_b)(l_b − c_b)` measured from
//! the centres of mass. The line between the anchors is
//!
//! ```text
//! d = (x_b + r_b) − (x_a + r_a),   L = ‖d‖,   n = d / L
//! ```
//!
//! and `L̇ = n · ḋ = n · (v_b + ω_b × r_b − v_a − ω_a × r_a)`, so every row
//! of the joint (`C = L − L₀`, `L − L_min`, `L_max − L`, the motor's
//! `Ċ = L̇`) has, up to its sign, the Jacobian
//!
//! ```text
//! J = [ −n   −(r_a × n)  │  n   r_b × n ]
//! K = J M⁻¹ Jᵀ = m_a⁻¹ + m_b⁻¹ + i_a⁻¹ (r_a × n)² + i_b⁻¹ (r_b × n)²
//! ```
//!
//! (an [`AxisRow`]; `∂(n·d)/∂θ` has no term from `∂n`, since `n ⊥ ∂n`).
//! An impulse `λ Jᵀ` gives the two bodies equal and opposite linear
//! impulses `∓λ n`, and its angular momentum about any point is
//! `λ ((x_b + r_b) − (x_a + r_a)) × n = λ d × n = 0`: the rows keep both
//! the linear and the angular momentum.
//!
//! **The rows**, solved in this order each iteration:
//!
//! | row    | when                                   | C            | impulse bounds            | softness |
//! |--------|----------------------------------------|--------------|---------------------------|----------|
//! | motor  | `enable_motor`                         | (velocity: `L̇ → motor_speed`) | `±max_motor_force · h` | rigid |
//! | length | no spring (`enable_spring` false), or limits with `min ≥ max` | `L − L₀` (`L₀` clamped into the limits) | none | [`JointDefBase::rigid_softness`] |
//! | spring | `enable_spring`, `hertz > 0`, not the row above | `L − L₀` | `[lower_force · h, upper_force · h]` | `Softness::new(hertz, damping_ratio, h)` |
//! | lower  | `enable_limit`, `min < max`            | `L − L_min ≥ 0` | `≥ 0`                  | rigid softness, speculative while apart |
//! | upper  | `enable_limit`, `min < max`            | `L_max − L ≥ 0` (`−J`) | `≥ 0`           | rigid softness, speculative while apart |
//!
//! A spring of 0 Hz is no row at all: that is a rope (the length row off,
//! slack below its maximum; see [`DistanceJointDef::rope`]). The rigid
//! rows' position feedback is capped at the joint correction speed; a
//! spring acts in the relax pass too (a spring is a force).
//!
//! **The direction** `n` is computed from the states' deltas every
//! iteration. When the anchors meet (`L` below [`MIN_AXIS_LENGTH`]) the
//! last direction is kept. The warm start applies the kept impulses along
//! the last direction the solve used (it is per body, so it cannot read
//! the other body's current position).
//!
//! **Through a portal** both ends are carried to their clones, scaled by
//! `η` about each object's centre of mass: the world-space lengths (rest,
//! minimum, maximum) and the motor speed scale by `η` too
//! ([`DistanceJoint::carry_through_portal`]).

use janus2d_core::body::{BodyHandle, BodySet, BodyState};
use janus2d_core::constraint::{Block, Constraint, ConstraintRows, StepContext};
use janus2d_core::limits::{MAX_EXTENT, MAX_SPEED};
use janus2d_core::math::{Real, Rot, Vec2, cross, vec_is_finite};
use janus2d_core::softness::Softness;

use crate::joint_base::{JointBase, RowsAt};
use crate::joint_def::{JointDefBase, KindDef, LimitsMut, MotorMut, SpringMut};
use crate::joint_rows::{Bounds, RowSolve, Terms, WarmSide};
use crate::kind_rows::{GeneralRows, KindRows, TreeRows};
use crate::parts::{AxisPart, AxisRow, PairMass};
use crate::{JointError, check_spring};

/// Below this distance between the anchors (m) the joint keeps the last
/// direction of its line instead of normalising a vector of rounding noise.
pub const MIN_AXIS_LENGTH: Real = 1.0e-6;

/// Everything needed to create a distance joint.
///
/// ```
/// use janus2d_constraints::{DistanceJointDef, JointError};
/// use janus2d_core::{BodyDef, BodySet, Vec2};
/// let mut bodies = BodySet::new();
/// let a = bodies.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// let b = bodies.create(&BodyDef::dynamic(Vec2::new(0.0, -2.0))).unwrap();
/// // A rigid rod of 2 m.
/// let rod = DistanceJointDef::new(a, b, Vec2::ZERO, Vec2::ZERO, 2.0);
/// assert!(rod.validate().is_ok());
/// // A rope: slack below 2.5 m.
/// let rope = DistanceJointDef::rope(a, b, Vec2::ZERO, Vec2::ZERO, 2.5);
/// assert!(rope.is_rope());
/// assert_eq!(
///     DistanceJointDef::rope(a, b, Vec2::ZERO, Vec2::ZERO, 0.0).validate(),
///     Err(JointError::ZeroLength)
/// );
/// // A spring of 2 Hz between 1.5 and 3 m.
/// let spring = rod.with_spring(2.0, 0.3).with_limits(1.5, 3.0);
/// assert!(spring.validate().is_ok());
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct DistanceJointDef {
    /// Bodies, frames (the anchors are the frames' origins; their angles
    /// are not used) and shared settings.
    pub base: JointDefBase,
    /// Rest length, m (> 0): the rigid row's length, the spring's rest
    /// length.
    pub length: Real,
    /// Enables the minimum and maximum lengths.
    pub enable_limit: bool,
    /// Minimum length, m (≥ 0).
    pub min_length: Real,
    /// Maximum length, m (> 0).
    pub max_length: Real,
    /// Makes the length row a spring (off: the length is held rigidly).
    pub enable_spring: bool,
    /// Spring stiffness, Hz (0 with the spring on: no length row at all,
    /// as a rope).
    pub hertz: Real,
    /// Spring damping ratio (dimensionless).
    pub damping_ratio: Real,
    /// Lower bound of the spring's force along the line, N (negative:
    /// the most tension it pulls with; `−∞`: unbounded).
    pub lower_force: Real,
    /// Upper bound of the spring's force along the line, N (positive:
    /// the most compression it pushes with; `∞`: unbounded).
    pub upper_force: Real,
    /// Enables the motor along the line.
    pub enable_motor: bool,
    /// Motor target speed of the length, m/s (positive lengthens).
    pub motor_speed: Real,
    /// Maximum motor force, N (finite, ≥ 0).
    pub max_motor_force: Real,
}

impl Default for DistanceJointDef {
    /// A rigid rod of 1 m between two placeholder bodies
    /// ([`JointDefBase::default`]: set `base.body_a` and `base.body_b`
    /// before use; `validate` refuses the placeholders as one body).
    fn default() -> Self {
        Self::from_base(JointDefBase::default(), 1.0)
    }
}

impl DistanceJointDef {
    /// A rigid rod of `length` (m) between two bodies at the given local
    /// anchors (m, in each body's frame).
    pub fn new(
        body_a: BodyHandle,
        body_b: BodyHandle,
        local_anchor_a: Vec2,
        local_anchor_b: Vec2,
        length: Real,
    ) -> Self {
        Self::from_base(
            JointDefBase::with_anchors(body_a, body_b, local_anchor_a, local_anchor_b),
            length,
        )
    }

    /// A rigid rod between two world points at the bodies' current poses,
    /// its length their distance (`Err(UnknownBody)` for a body not in
    /// `bodies`; a zero distance fails validation as
    /// [`JointError::ZeroLength`]).
    pub fn at_world_points(
        bodies: &BodySet,
        body_a: BodyHandle,
        body_b: BodyHandle,
        point_a: Vec2,
        point_b: Vec2,
    ) -> Result<Self, JointError> {
        if !(vec_is_finite(point_a) && vec_is_finite(point_b)) {
            return Err(JointError::NonFinite);
        }
        let local = |body: BodyHandle, p: Vec2| -> Result<Vec2, JointError> {
            let xf = bodies.sim(body).ok_or(JointError::UnknownBody)?.transform;
            Ok(xf.apply_inv(p))
        };
        Ok(Self::new(
            body_a,
            body_b,
            local(body_a, point_a)?,
            local(body_b, point_b)?,
            (point_b - point_a).length(),
        ))
    }

    /// A rope of `max_length` (m): no length row (the spring on at 0 Hz),
    /// the maximum only (minimum 0), slack below it.
    pub fn rope(
        body_a: BodyHandle,
        body_b: BodyHandle,
        local_anchor_a: Vec2,
        local_anchor_b: Vec2,
        max_length: Real,
    ) -> Self {
        DistanceJointDef {
            enable_spring: true,
            hertz: 0.0,
            enable_limit: true,
            min_length: 0.0,
            max_length,
            ..Self::new(body_a, body_b, local_anchor_a, local_anchor_b, max_length)
        }
    }

    /// A rigid rod of `length` (m) on a shared base (frames, thresholds,
    /// softness); limits, spring and motor off.
    pub fn from_base(base: JointDefBase, length: Real) -> Self {
        DistanceJointDef {
            base,
            length,
            enable_limit: false,
            min_length: 0.0,
            max_length: MAX_EXTENT,
            enable_spring: false,
            hertz: 0.0,
            damping_ratio: 0.0,
            lower_force: Real::NEG_INFINITY,
            upper_force: Real::INFINITY,
            enable_motor: false,
            motor_speed: 0.0,
            max_motor_force: 0.0,
        }
    }

    /// Enables the minimum and maximum lengths, m (builder style).
    pub fn with_limits(mut self, min_length: Real, max_length: Real) -> Self {
        self.enable_limit = true;
        self.min_length = min_length;
        self.max_length = max_length;
        self
    }

    /// Makes the length row a spring of `hertz` (Hz) and `damping_ratio`
    /// (builder style).
    pub fn with_spring(mut self, hertz: Real, damping_ratio: Real) -> Self {
        self.enable_spring = true;
        self.hertz = hertz;
        self.damping_ratio = damping_ratio;
        self
    }

    /// Bounds the spring's force to `[lower, upper]`, N (builder style).
    pub fn with_spring_force_range(mut self, lower: Real, upper: Real) -> Self {
        self.lower_force = lower;
        self.upper_force = upper;
        self
    }

    /// Enables the motor: target length speed (m/s) and maximum force (N)
    /// (builder style).
    pub fn with_motor(mut self, speed: Real, max_force: Real) -> Self {
        self.enable_motor = true;
        self.motor_speed = speed;
        self.max_motor_force = max_force;
        self
    }

    /// Lets the two bodies collide (builder style).
    pub fn with_collide_connected(mut self, on: bool) -> Self {
        self.base.collide_connected = on;
        self
    }

    /// True when the length is held rigidly: the spring off, or limits
    /// that leave no range (`min ≥ max`).
    #[must_use]
    pub fn is_rigid(&self) -> bool {
        !self.enable_spring || self.limits_closed()
    }

    /// True for a rope: no length row (the spring on at 0 Hz) and a
    /// maximum length.
    #[must_use]
    pub fn is_rope(&self) -> bool {
        !self.is_rigid() && self.hertz == 0.0 && self.enable_limit
    }

    /// Limits on with no range between them.
    fn limits_closed(&self) -> bool {
        self.enable_limit && self.min_length >= self.max_length
    }

    /// Limits on with a range between them: the two limit rows act.
    fn limits_open(&self) -> bool {
        self.enable_limit && self.min_length < self.max_length
    }

    /// The length the rigid row holds: `length`, clamped into the limits
    /// when they are on, m.
    #[must_use]
    pub fn rigid_length(&self) -> Real {
        if self.enable_limit {
            self.length.max(self.min_length).min(self.max_length)
        } else {
            self.length
        }
    }

    /// Checks the definition's own values (not the handles): finite
    /// lengths, speed, spring and force bounds (the force bounds may be
    /// infinite, not NaN); `length > 0` and `max_length > 0`
    /// ([`JointError::ZeroLength`]); `min_length ≥ 0`, `hertz`,
    /// `damping_ratio` and `max_motor_force ≥ 0` ([`JointError::Negative`]);
    /// `min_length ≤ max_length` when the limits are on and
    /// `lower_force ≤ upper_force` ([`JointError::InvalidLimits`]); lengths
    /// up to [`MAX_EXTENT`], the motor speed up to [`MAX_SPEED`].
    pub fn validate(&self) -> Result<(), JointError> {
        self.base.validate()?;
        let finite = self.length.is_finite()
            && self.min_length.is_finite()
            && self.max_length.is_finite()
            && self.hertz.is_finite()
            && self.damping_ratio.is_finite()
            && !self.lower_force.is_nan()
            && !self.upper_force.is_nan()
            && self.motor_speed.is_finite()
            && self.max_motor_force.is_finite();
        if !finite {
            return Err(JointError::NonFinite);
        }
        if self.length <= 0.0 || self.max_length <= 0.0 {
            return Err(JointError::ZeroLength);
        }
        if self.min_length < 0.0
            || self.hertz < 0.0
            || self.damping_ratio < 0.0
            || self.max_motor_force < 0.0
        {
            return Err(JointError::Negative);
        }
        if (self.enable_limit && self.min_length > self.max_length)
            || self.lower_force > self.upper_force
        {
            return Err(JointError::InvalidLimits);
        }
        for (value, field) in [
            (self.length, "length"),
            (self.min_length, "min_length"),
            (self.max_length, "max_length"),
        ] {
            if value > MAX_EXTENT {
                return Err(JointError::OutOfBounds {
                    field,
                    min: 0.0,
                    max: MAX_EXTENT,
                });
            }
        }
        if self.motor_speed.abs() > MAX_SPEED {
            return Err(JointError::OutOfBounds {
                field: "motor_speed",
                min: -MAX_SPEED,
                max: MAX_SPEED,
            });
        }
        check_spring(self.hertz, self.damping_ratio)
    }
}

impl KindDef for DistanceJointDef {
    fn base(&self) -> &JointDefBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointDefBase {
        &mut self.base
    }
    fn validate(&self) -> Result<(), JointError> {
        DistanceJointDef::validate(self)
    }
    fn limits_mut(&mut self) -> Option<LimitsMut<'_>> {
        Some(LimitsMut {
            enable: &mut self.enable_limit,
            lower: &mut self.min_length,
            upper: &mut self.max_length,
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

/// A distance joint in solver form.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(C)]
pub struct DistanceJoint {
    /// State indices, masses and switches the solver reads.
    pub(crate) base: JointBase,
    /// The definition it was made from (lengths, spring and motor as last
    /// set).
    pub(crate) def: Box<DistanceJointDef>,
    /// Anchor on a relative to a's centre at the start of the step (world
    /// frame), m.
    frame_a: Vec2,
    /// Anchor on b relative to b's centre at the start of the step, m.
    frame_b: Vec2,
    /// `c_b − c_a` at the start of the step, m.
    delta_center: Vec2,
    /// The line's direction `n` (unit, a to b) the solve last used.
    axis: Vec2,
    /// The length row (rigid) or the spring row: they never act together.
    length_row: AxisPart,
    /// The lower limit row (`L − L_min ≥ 0`).
    lower: AxisPart,
    /// The upper limit row (`L_max − L ≥ 0`, along `−n`).
    upper: AxisPart,
    /// The motor row.
    motor: AxisPart,
    /// Softness of the rigid rows (length, limits) for this step.
    rigid_softness: Softness,
    /// Softness of the spring for this step.
    spring_softness: Softness,
}

/// The softness of the rigid rows (length, limits): the joint's own or the
/// world's, built on the heavier end's mass. Used by the solve and
/// reported by `rows()`.
fn rigid_softness(def: &DistanceJointDef, ctx: &StepContext, m: &PairMass) -> Softness {
    def.base.rigid_softness(ctx, m.a.inv_mass, m.b.inv_mass)
}

/// `c` (m) with its feedback speed `bias_rate · c` capped at `max_speed`
/// (m/s; `Real::MAX`: no cap).
fn capped(c: Real, softness: Softness, max_speed: Real) -> Real {
    if softness.bias_rate > 0.0 && max_speed < Real::MAX {
        let limit = max_speed / softness.bias_rate;
        c.clamp(-limit, limit)
    } else {
        c
    }
}

impl DistanceJoint {
    /// A joint from a definition (validate it first).
    pub fn new(def: DistanceJointDef) -> Self {
        DistanceJoint {
            def: Box::new(def),
            base: JointBase::default(),
            frame_a: Vec2::ZERO,
            frame_b: Vec2::ZERO,
            delta_center: Vec2::ZERO,
            axis: Vec2::X,
            length_row: AxisPart::default(),
            lower: AxisPart::default(),
            upper: AxisPart::default(),
            motor: AxisPart::default(),
            rigid_softness: Softness::RIGID,
            spring_softness: Softness::RIGID,
        }
    }

    /// True when the length row or the spring row acts.
    fn has_length_row(&self) -> bool {
        self.def.is_rigid() || self.def.hertz > 0.0
    }

    /// Rows this joint adds to the solver when enabled: the length (rigid
    /// or spring, none for a rope), the motor, and the two limits when
    /// they leave a range.
    #[must_use]
    pub fn row_count(&self) -> usize {
        usize::from(self.has_length_row())
            + usize::from(self.def.enable_motor)
            + 2 * usize::from(self.def.limits_open())
    }

    /// Carries the joint through a portal when both ends move to the other
    /// side (`rotation = Q`, `scale = 1/η`). The world scales the anchors
    /// by `η` about each object's centre of mass, so every world-space
    /// length of the joint does the same: rest, minimum and maximum length
    /// and the motor speed are multiplied by `η = 1/scale` (the joint holds
    /// the image of what it held). The impulses are along the line: they
    /// scale by `1/η` like the revolute joint's point impulse (their
    /// direction follows the line, recomputed from the bodies); the kept
    /// direction turns by `Q`.
    pub fn carry_through_portal(&mut self, rotation: Rot, scale: Real) {
        let eta = 1.0 / scale;
        let def = &mut self.def;
        def.length *= eta;
        def.min_length *= eta;
        def.max_length = (def.max_length * eta).min(MAX_EXTENT);
        def.motor_speed *= eta;
        for part in [
            &mut self.length_row,
            &mut self.lower,
            &mut self.upper,
            &mut self.motor,
        ] {
            part.impulse *= scale;
        }
        self.axis = rotation.rotate(self.axis);
    }

    /// The world anchors on a and b, m.
    pub fn world_anchors(&self, bodies: &BodySet) -> (Vec2, Vec2) {
        self.def.base.world_anchors(bodies)
    }

    /// The distance between the two world anchors, m.
    pub fn current_length(&self, bodies: &BodySet) -> Real {
        let (pa, pb) = self.world_anchors(bodies);
        (pb - pa).length()
    }

    /// False when the joint is disabled (skipped by the solver).
    #[must_use]
    pub fn is_enabled(&self) -> bool {
        self.base.enabled
    }

    /// The impulse along the line (positive pushes the anchors apart) of
    /// one substep of the last solved step, N·s: length or spring, motor
    /// and limits together.
    #[must_use]
    pub fn axial_impulse(&self) -> Real {
        self.length_row.impulse + self.motor.impulse + self.lower.impulse - self.upper.impulse
    }

    /// The force along the line (positive pushes the anchors apart: a
    /// rope or rod holding a weight reads negative, tension), N, over the
    /// last solved step.
    #[must_use]
    pub fn axial_force(&self) -> Real {
        self.axial_impulse() * self.base.inv_h
    }

    /// Force the joint applies to body b over the last solved step, N
    /// (along the line; body a gets the opposite). A 10 kg bob hanging on
    /// a rope under g = 10 m/s² reads 100 N upwards.
    #[must_use]
    pub fn constraint_force(&self) -> Vec2 {
        self.axial_force() * self.axis
    }

    /// Torque on body b over the last solved step about its anchor: 0 (the
    /// joint only pulls along its line), N·m.
    #[must_use]
    pub fn constraint_torque(&self) -> Real {
        0.0
    }

    /// Motor impulse of one substep of the last solved step, N·s.
    #[must_use]
    pub fn motor_impulse(&self) -> Real {
        self.motor.impulse
    }

    /// The arms and the line `d` from the states' deltas.
    #[inline(always)]
    fn arms(&self, sa: &BodyState, sb: &BodyState) -> (Vec2, Vec2, Vec2) {
        let r_a = sa.dq.rotate(self.frame_a);
        let r_b = sb.dq.rotate(self.frame_b);
        let d = (sb.dp - sa.dp) + self.delta_center + (r_b - r_a);
        (r_a, r_b, d)
    }
}

impl KindRows for DistanceJoint {
    fn base(&self) -> &JointBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointBase {
        &mut self.base
    }
    fn row_count(&self) -> usize {
        DistanceJoint::row_count(self)
    }
    fn is_driven(&self) -> bool {
        self.def.enable_motor && self.def.max_motor_force > 0.0
    }
    fn constraint_force(&self) -> Vec2 {
        DistanceJoint::constraint_force(self)
    }
    fn constraint_torque(&self) -> Real {
        DistanceJoint::constraint_torque(self)
    }
    fn carry_through_portal(&mut self, rotation: Rot, scale: Real) {
        DistanceJoint::carry_through_portal(self, rotation, scale);
    }
    /// The kept impulse along the line (every row's, summed), at the
    /// body's current arm.
    #[inline(always)]
    fn warm_rows(&self, w: &mut WarmSide<'_>) {
        w.linear_at_arms(
            self.axis,
            (self.frame_a, self.frame_b),
            self.axial_impulse(),
        );
    }
    /// The rows along the anchors' line: motor, then the rigid length or
    /// the spring, then the limits.
    #[inline(always)]
    fn solve_rows(&mut self, ctx: &StepContext, use_bias: bool, s: &mut RowSolve) {
        let (r_a, r_b, d) = self.arms(&s.sa, &s.sb);
        let length = d.length();
        if length > MIN_AXIS_LENGTH {
            self.axis = d / length;
        }
        let n = self.axis;
        let row = AxisRow::new(&s.m, n, cross(r_a, n), cross(r_b, n));
        let def = &self.def;
        if def.enable_motor {
            let bounds = Bounds::symmetric(ctx.h * def.max_motor_force);
            s.linear(
                &row,
                Terms::motor(def.motor_speed),
                bounds,
                &mut self.motor.impulse,
            );
        }
        // The length row's impulse is clamped (not summed) even where free.
        let free = Bounds::Clamp(Real::NEG_INFINITY, Real::INFINITY);
        if def.is_rigid() && !self.base.in_tree {
            let t = if use_bias {
                let soft = self.rigid_softness;
                let c = capped(
                    length - def.rigid_length(),
                    soft,
                    ctx.joint_max_correction_speed,
                );
                Terms::soft(soft, c, Real::INFINITY)
            } else {
                Terms::soft(Softness::RIGID, 0.0, Real::INFINITY)
            };
            s.linear(&row, t, free, &mut self.length_row.impulse);
        } else if def.hertz > 0.0 {
            // A spring: always on (relax pass too), its bias not capped.
            let t = Terms::soft(self.spring_softness, length - def.length, Real::INFINITY);
            let bounds = Bounds::Clamp(ctx.h * def.lower_force, ctx.h * def.upper_force);
            s.linear(&row, t, bounds, &mut self.length_row.impulse);
        }
        if def.limits_open() {
            let soft = self.rigid_softness;
            let cap = ctx.joint_max_correction_speed;
            // Speculative while apart (uncapped), capped feedback when
            // violated (capped here: no second cap in the row).
            let violated = |c: Real| if c > 0.0 { c } else { capped(c, soft, cap) };
            let lower = Terms::limit(
                violated(length - def.min_length),
                soft,
                ctx.inv_h,
                use_bias,
                Real::INFINITY,
            );
            s.linear(&row, lower, Bounds::ONE_SIDED, &mut self.lower.impulse);
            let flipped = AxisRow {
                n: -row.n,
                s_a: -row.s_a,
                s_b: -row.s_b,
                mass: row.mass,
            };
            let upper = Terms::limit(
                violated(def.max_length - length),
                soft,
                ctx.inv_h,
                use_bias,
                Real::INFINITY,
            );
            s.linear(&flipped, upper, Bounds::ONE_SIDED, &mut self.upper.impulse);
        }
    }
    /// A rigid length row joins the exact tree solve (unless the joint has
    /// its own constraint softness); the spring, limits and motor stay
    /// iterative, so it always has a Gauss–Seidel pass (which also keeps
    /// the line's direction current).
    #[inline(always)]
    fn tree_rows(&self) -> Option<TreeRows<'_>> {
        (self.def.is_rigid() && self.def.base.constraint_hertz == 0.0)
            .then_some(TreeRows::General { count: 1 })
    }
    #[inline(always)]
    fn tree_general_rows(&self, sa: &BodyState, sb: &BodyState) -> GeneralRows {
        let (r_a, r_b, d) = self.arms(sa, sb);
        let length = d.length();
        let n = if length > MIN_AXIS_LENGTH {
            d / length
        } else {
            self.axis
        };
        GeneralRows {
            count: 1,
            j_a: [[-n.x, -n.y, -cross(r_a, n)], [0.0; 3], [0.0; 3]],
            j_b: [[n.x, n.y, cross(r_b, n)], [0.0; 3], [0.0; 3]],
            c: [length - self.def.rigid_length(), 0.0, 0.0],
            linear: [true, false, false],
            impulse: [self.length_row.impulse, 0.0, 0.0],
        }
    }
    #[inline(always)]
    fn set_tree_impulses(&mut self, impulses: [Real; 3]) {
        self.length_row.impulse = impulses[0];
    }
    #[inline(always)]
    fn has_iterative_rows(&self) -> bool {
        true
    }
}

impl Constraint for DistanceJoint {
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        let Some((a, b)) = self
            .base
            .load(ctx, bodies, self.def.base.body_a, self.def.base.body_b)
        else {
            return;
        };
        let q_a = a.sim.transform.q;
        let q_b = b.sim.transform.q;
        self.frame_a = q_a.rotate(self.def.base.local_frame_a.anchor - a.sim.local_center);
        self.frame_b = q_b.rotate(self.def.base.local_frame_b.anchor - b.sim.local_center);
        self.delta_center = b.sim.center - a.sim.center;
        let d = self.delta_center + self.frame_b - self.frame_a;
        let length = d.length();
        if length > MIN_AXIS_LENGTH {
            self.axis = d / length;
        }
        let m = self.base.masses;
        self.rigid_softness = rigid_softness(&self.def, ctx, &m);
        self.spring_softness = Softness::new(self.def.hertz, self.def.damping_ratio, ctx.h);
        if !ctx.warm_starting {
            self.length_row.impulse = 0.0;
            self.lower.impulse = 0.0;
            self.upper.impulse = 0.0;
            self.motor.impulse = 0.0;
        }
        if !self.has_length_row() {
            self.length_row.impulse = 0.0;
        }
        if !self.def.enable_motor {
            self.motor.impulse = 0.0;
        }
        if !self.def.limits_open() {
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
        let (m, r_a, r_b, d) = (at.m, at.r_a, at.r_b, at.c);
        let length = d.length();
        let n = if length > MIN_AXIS_LENGTH {
            d / length
        } else {
            self.axis
        };
        let k = AxisRow::new(&m, n, cross(r_a, n), cross(r_b, n)).k();
        let rigid = rigid_softness(&self.def, ctx, &m);
        let def = &self.def;
        let mut out = ConstraintRows::default();
        let mut push = |sign: Real, c: Real, softness: Softness, bounds: (Real, Real), impulse| {
            let mut row = at.point_row(sign * n, c, softness, impulse);
            (row.lower, row.upper) = bounds;
            out.blocks.push(Block {
                first_row: out.rows.len(),
                len: 1,
                k: [[k, 0.0, 0.0], [0.0; 3], [0.0; 3]],
            });
            out.rows.push(row);
        };
        if def.enable_motor {
            let max = ctx.h * def.max_motor_force;
            push(1.0, 0.0, Softness::RIGID, (-max, max), self.motor.impulse);
        }
        if def.is_rigid() {
            let free = (Real::NEG_INFINITY, Real::INFINITY);
            push(
                1.0,
                length - def.rigid_length(),
                rigid,
                free,
                self.length_row.impulse,
            );
        } else if def.hertz > 0.0 {
            push(
                1.0,
                length - def.length,
                Softness::new(def.hertz, def.damping_ratio, ctx.h),
                (ctx.h * def.lower_force, ctx.h * def.upper_force),
                self.length_row.impulse,
            );
        }
        if def.limits_open() {
            let one_sided = (0.0, Real::INFINITY);
            push(
                1.0,
                length - def.min_length,
                rigid,
                one_sided,
                self.lower.impulse,
            );
            push(
                -1.0,
                def.max_length - length,
                rigid,
                one_sided,
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

    /// Two moving bodies and a distance joint with every row, prepared,
    /// with nonzero kept impulses.
    fn prepared() -> (BodySet, DistanceJoint, StepContext) {
        let mut set = BodySet::new();
        let a = set
            .create(
                &BodyDef::dynamic(Vec2::new(0.3, -0.2))
                    .with_mass(2.0, 0.3)
                    .with_angle(0.4),
            )
            .unwrap();
        let b = set
            .create(
                &BodyDef::dynamic(Vec2::new(1.7, 0.9))
                    .with_mass(0.5, 0.05)
                    .with_angle(-1.1),
            )
            .unwrap();
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
        let def = DistanceJointDef::new(a, b, Vec2::new(0.1, 0.2), Vec2::new(-0.3, 0.1), 1.5)
            .with_limits(1.0, 2.0)
            .with_motor(0.5, 10.0);
        let mut joint = DistanceJoint::new(def);
        joint.prepare(&ctx, &set);
        joint.length_row.impulse = 0.3;
        joint.motor.impulse = -0.2;
        joint.lower.impulse = 0.05;
        joint.upper.impulse = 0.7;
        (set, joint, ctx)
    }

    #[test]
    fn rows_follow_the_switches() {
        let (set, joint, ctx) = prepared();
        assert_eq!(joint.rows(&ctx, &set).rows.len(), 4);
        let (a, b) = (joint.def.base.body_a, joint.def.base.body_b);
        let rope = DistanceJoint::new(DistanceJointDef::rope(a, b, Vec2::ZERO, Vec2::ZERO, 2.0));
        assert!(rope.def.is_rope() && !rope.def.is_rigid());
        assert_eq!(rope.row_count(), 2);
        assert_eq!(rope.rows(&ctx, &set).rows.len(), 2);
        // Limits with no range: the rigid row at the clamped length.
        let closed = DistanceJointDef::new(a, b, Vec2::ZERO, Vec2::ZERO, 3.0)
            .with_spring(2.0, 0.5)
            .with_limits(1.5, 1.5);
        assert!(closed.is_rigid());
        assert_eq!(closed.rigid_length(), 1.5);
        assert_eq!(DistanceJoint::new(closed).row_count(), 1);
    }
}
