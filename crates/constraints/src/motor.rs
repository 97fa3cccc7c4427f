//! The motor joint (Box2D's motor joint): drives body b's pose relative to
//! body a toward a target offset and angle, with a largest force and
//! torque (a character riding a platform, the drag of a top-down car).
//!
//! # Derivation
//!
//! Bodies `a` and `b` with centres `x_a`, `x_b`, angles `θ_a`, `θ_b`. The
//! target of b's frame anchor `l_b` is a point fixed on body a: the linear
//! offset `o` taken in a's joint frame, `t_a = l_a + R(φ_a) o` (body a's
//! frame; `l_a`, `φ_a` the origin and angle of frame a). With the arms from
//! the centres of mass `r_a = R(θ_a)(t_a − c_a)`, `r_b = R(θ_b)(l_b − c_b)`:
//!
//! **Linear (2 rows).** `C_p = (x_b + r_b) − (x_a + r_a)`, the revolute
//! joint's point rows between `t_a` and `l_b`:
//!
//! ```text
//! J_p = [ −I  −perp(r_a)   I  perp(r_b) ]
//! K_p = (m_a⁻¹ + m_b⁻¹) I + i_a⁻¹ perp(r_a) perp(r_a)ᵀ + i_b⁻¹ perp(r_b) perp(r_b)ᵀ
//! ```
//!
//! Because the target is a point of body a (not the anchor plus an offset
//! frozen in the world for the step), `J_p` is the exact derivative of
//! `C_p`, also when a turns.
//!
//! **Angular (1 row).** `C_θ = θ_b − θ_a − θ_ref − θ_off` (wrapped to
//! `[−π, π]`; `θ_ref = φ_a − φ_b` the reference angle, `θ_off` the angular
//! offset), `J_θ = [0 0 −1 │ 0 0 1]`, `K_θ = i_a⁻¹ + i_b⁻¹`.
//!
//! **The drive.** Each row targets the velocity that closes the fraction
//! `β = correction_factor` of its error in one substep (Box2D's motor
//! joint): `λ = −K⁻¹ (Ċ + β C / h)`, accumulated, and the accumulated
//! impulse clamped: the angular one to `±max_torque · h`, the linear one
//! to a length of at most `max_force · h` (a force of at most `max_force`
//! in any direction). The drive is a bounded force, not a position
//! correction: it acts in the relax pass too, so the relax pass does not
//! spend the force budget braking the drive's own velocity. The angular
//! row is solved first, then the linear pair, as in Box2D.
//!
//! With both offsets 0, a fixed body a and `correction_factor` 0, the joint
//! is a friction-like drag: the force (torque) brakes b's velocity
//! (spin) by at most `max_force` (`max_torque`), as a top-down car's tyres.
//!
//! **Through a portal.** The linear offset is a length in a's frame: when
//! both ends cross a portal of scale `η` the pair is `η` times larger on the
//! exit side, so [`MotorJoint::carry_through_portal`] scales the offset by `η`
//! (as it scales the anchors), turns the linear impulse by `Q` and scales
//! it by `1/η`; the angular offset, impulse and the largest force and
//! torque are kept.

use janus2d_core::body::{BodyHandle, BodySet, BodyState};
use janus2d_core::constraint::{Block, Constraint, ConstraintRows, StepContext};
use janus2d_core::math::{Real, Rot, Vec2, vec_is_finite, wrap_angle};
use janus2d_core::softness::Softness;

use crate::joint_base::{JointBase, RowsAt};
use crate::joint_def::{JointDefBase, KindDef};
use crate::joint_rows::{Bounds, PointTerms, RowSolve, Terms, WarmSide, point_bound};
use crate::kind_rows::KindRows;
use crate::parts::{AnglePart, PointPart};
use crate::{JointError, check_anchor};

/// Everything needed to create a motor joint.
///
/// ```
/// use janus2d_constraints::{JointError, MotorJointDef};
/// use janus2d_core::{BodyDef, BodySet, Vec2};
/// let mut bodies = BodySet::new();
/// let platform = bodies.create(&BodyDef::kinematic(Vec2::ZERO)).unwrap();
/// let rider = bodies.create(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
/// // Hold the rider 1 m above the platform's origin, upright, with up to
/// // 500 N and 50 N·m.
/// let def = MotorJointDef::new(platform, rider)
///     .with_offset(Vec2::new(0.0, 1.0), 0.0)
///     .with_max_force(500.0)
///     .with_max_torque(50.0)
///     .with_correction_factor(0.5);
/// assert!(def.validate().is_ok());
/// // The same from the bodies' current poses.
/// let here = MotorJointDef::at_current_pose(&bodies, platform, rider).unwrap();
/// assert_eq!(here.linear_offset, Vec2::new(0.0, 1.0));
/// assert!(matches!(
///     def.clone().with_correction_factor(1.5).validate(),
///     Err(JointError::OutOfBounds { .. })
/// ));
/// assert_eq!(def.with_max_force(-1.0).validate(), Err(JointError::Negative));
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MotorJointDef {
    /// Bodies, frames (frame a is the frame the offsets are taken in,
    /// frame b's anchor the point driven to the target; the reference
    /// angle is `φ_a − φ_b`) and shared settings.
    pub base: JointDefBase,
    /// Target position of b's frame anchor relative to a's frame origin,
    /// in a's joint frame, m.
    pub linear_offset: Vec2,
    /// Target joint angle `θ_b − θ_a − θ_ref`, rad.
    pub angular_offset: Real,
    /// Largest force of the linear drive, N (≥ 0; ∞ allowed).
    pub max_force: Real,
    /// Largest torque of the angular drive, N·m (≥ 0; ∞ allowed).
    pub max_torque: Real,
    /// Fraction of the pose error the drive closes per substep
    /// (dimensionless, in `[0, 1]`): the target velocity is
    /// `correction_factor · C / h`.
    pub correction_factor: Real,
}

impl Default for MotorJointDef {
    /// A motor joint at zero offsets with the default force and torque between two placeholder bodies
    /// ([`JointDefBase::default`]: set `base.body_a` and `base.body_b`
    /// before use; `validate` refuses the placeholders as one body).
    fn default() -> Self {
        Self::from_base(JointDefBase::default())
    }
}

impl MotorJointDef {
    /// A motor joint between `body_a` and `body_b`: frames at the bodies'
    /// origins, both offsets 0 (b driven onto a's origin and angle), and
    /// Box2D's defaults `max_force` 1 N, `max_torque` 1 N·m,
    /// `correction_factor` 0.3.
    pub fn new(body_a: BodyHandle, body_b: BodyHandle) -> Self {
        Self::from_base(JointDefBase::new(body_a, body_b))
    }

    /// A motor joint on a shared base, offsets 0, Box2D's defaults.
    pub fn from_base(base: JointDefBase) -> Self {
        MotorJointDef {
            base,
            linear_offset: Vec2::ZERO,
            angular_offset: 0.0,
            max_force: 1.0,
            max_torque: 1.0,
            correction_factor: 0.3,
        }
    }

    /// A motor joint whose offsets hold the bodies' current relative pose
    /// (frames at the origins: the offset is b's origin in a's frame, the
    /// angle `θ_b − θ_a`); `Err(UnknownBody)` for a body not in `bodies`.
    pub fn at_current_pose(
        bodies: &BodySet,
        body_a: BodyHandle,
        body_b: BodyHandle,
    ) -> Result<Self, JointError> {
        let xf_a = bodies.sim(body_a).ok_or(JointError::UnknownBody)?.transform;
        let xf_b = bodies.sim(body_b).ok_or(JointError::UnknownBody)?.transform;
        Ok(Self::new(body_a, body_b)
            .with_offset(xf_a.apply_inv(xf_b.p), xf_a.q.relative_angle(xf_b.q)))
    }

    /// Sets the linear (m, in a's joint frame) and angular (rad) offsets
    /// (builder style).
    pub fn with_offset(mut self, linear: Vec2, angular: Real) -> Self {
        self.linear_offset = linear;
        self.angular_offset = angular;
        self
    }

    /// Sets the largest force, N (builder style).
    pub fn with_max_force(mut self, force: Real) -> Self {
        self.max_force = force;
        self
    }

    /// Sets the largest torque, N·m (builder style).
    pub fn with_max_torque(mut self, torque: Real) -> Self {
        self.max_torque = torque;
        self
    }

    /// Sets the correction factor, in `[0, 1]` (builder style).
    pub fn with_correction_factor(mut self, factor: Real) -> Self {
        self.correction_factor = factor;
        self
    }

    /// The target point on body a, in a's body frame (from its origin), m:
    /// frame a's origin plus the linear offset turned by frame a's angle.
    #[must_use]
    pub fn target_anchor_a(&self) -> Vec2 {
        let frame = &self.base.local_frame_a;
        frame.anchor + Rot::from_angle(frame.angle).rotate(self.linear_offset)
    }

    /// Checks the definition's own values (not the handles): the base, a
    /// finite offset within
    /// [`MAX_EXTENT`](janus2d_core::limits::MAX_EXTENT), a non-negative
    /// (not NaN) force and torque, a correction factor in `[0, 1]`.
    pub fn validate(&self) -> Result<(), JointError> {
        self.base.validate()?;
        let finite = vec_is_finite(self.linear_offset)
            && self.angular_offset.is_finite()
            && !self.max_force.is_nan()
            && !self.max_torque.is_nan()
            && self.correction_factor.is_finite();
        if !finite {
            return Err(JointError::NonFinite);
        }
        if self.max_force < 0.0 || self.max_torque < 0.0 {
            return Err(JointError::Negative);
        }
        if !(0.0..=1.0).contains(&self.correction_factor) {
            return Err(JointError::OutOfBounds {
                field: "correction_factor",
                min: 0.0,
                max: 1.0,
            });
        }
        check_anchor(self.linear_offset, "linear_offset")?;
        let max_angle = janus2d_core::limits::MAX_EXTENT;
        if self.angular_offset.abs() > max_angle {
            return Err(JointError::OutOfBounds {
                field: "angular_offset",
                min: -max_angle,
                max: max_angle,
            });
        }
        Ok(())
    }
}

impl KindDef for MotorJointDef {
    fn base(&self) -> &JointDefBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointDefBase {
        &mut self.base
    }
    fn validate(&self) -> Result<(), JointError> {
        MotorJointDef::validate(self)
    }
}

/// A motor joint in solver form.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(C)]
pub struct MotorJoint {
    /// State indices, masses and switches the solver reads.
    pub(crate) base: JointBase,
    /// The definition it was made from.
    pub(crate) def: Box<MotorJointDef>,
    /// The linear rows (target point on a, anchor on b).
    pub(crate) point: PointPart,
    /// The angular row.
    pub(crate) angle: AnglePart,
    /// `C_θ` at the start of the step, rad.
    pub(crate) delta_angle: Real,
    /// `β / h` of this step, 1/s.
    bias_rate: Real,
    /// `max_force · h` of this step, N·s.
    max_linear_impulse: Real,
    /// `max_torque · h` of this step, N·m·s.
    max_angular_impulse: Real,
}

impl MotorJoint {
    /// A joint from a definition (validate it first).
    pub fn new(def: MotorJointDef) -> Self {
        MotorJoint {
            def: Box::new(def),
            base: JointBase::default(),
            point: PointPart::default(),
            angle: AnglePart::default(),
            delta_angle: 0.0,
            bias_rate: 0.0,
            max_linear_impulse: 0.0,
            max_angular_impulse: 0.0,
        }
    }

    /// Rows this joint adds to the solver when enabled: two linear rows
    /// and one angular row.
    #[must_use]
    pub fn row_count(&self) -> usize {
        3
    }

    /// Carries the joint through a portal when both ends move to the
    /// other side (`rotation = Q`, `scale = 1/η`): the linear impulse
    /// turns and scales as [`crate::RevoluteJoint::carry_through_portal`], and
    /// the linear offset, a length in a's frame, scales by `η` with the
    /// pair (the frames' angles are kept, so it does not turn). The
    /// angular offset and impulse, `max_force` and `max_torque` are kept.
    pub fn carry_through_portal(&mut self, rotation: Rot, scale: Real) {
        self.point.impulse = scale * rotation.rotate(self.point.impulse);
        if scale > 0.0 && scale.is_finite() {
            self.def.linear_offset /= scale;
        }
    }

    /// The world points the drive brings together: the target on a and
    /// b's frame anchor, m.
    pub fn world_targets(&self, bodies: &BodySet) -> (Vec2, Vec2) {
        crate::joint_def::world_anchors(
            bodies,
            (self.def.base.body_a, self.def.target_anchor_a()),
            (self.def.base.body_b, self.def.base.local_frame_b.anchor),
        )
    }

    /// The linear error: b's anchor minus its target, world frame, m.
    pub fn linear_error(&self, bodies: &BodySet) -> Vec2 {
        let (target, anchor) = self.world_targets(bodies);
        anchor - target
    }

    /// The angular error `θ_b − θ_a − θ_ref − θ_off`, rad (wrapped to
    /// `[−π, π]`).
    pub fn angular_error(&self, bodies: &BodySet) -> Real {
        crate::joint_base::relative_angle(
            bodies,
            self.def.base.body_a,
            self.def.base.body_b,
            self.def.base.reference_angle() + self.def.angular_offset,
        )
    }

    /// False when the joint is disabled (skipped by the solver).
    #[must_use]
    pub fn is_enabled(&self) -> bool {
        self.base.enabled
    }

    /// Linear impulse of one substep of the last solved step, N·s.
    pub fn linear_impulse(&self) -> Vec2 {
        self.point.impulse
    }

    /// Angular impulse of one substep of the last solved step, N·m·s.
    pub fn angular_impulse(&self) -> Real {
        self.angle.impulse
    }

    /// Force the drive applies to body b over the last solved step, N
    /// (body a gets the opposite; its length is at most `max_force`).
    #[must_use]
    pub fn constraint_force(&self) -> Vec2 {
        self.point.impulse * self.base.inv_h
    }

    /// Torque the angular drive applies to body b over the last solved
    /// step, N·m (at most `max_torque` in size; body a gets the opposite).
    #[must_use]
    pub fn constraint_torque(&self) -> Real {
        self.angle.impulse * self.base.inv_h
    }
}

impl KindRows for MotorJoint {
    fn base(&self) -> &JointBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointBase {
        &mut self.base
    }
    fn row_count(&self) -> usize {
        MotorJoint::row_count(self)
    }
    fn is_driven(&self) -> bool {
        self.def.max_force > 0.0 || self.def.max_torque > 0.0
    }
    fn constraint_force(&self) -> Vec2 {
        MotorJoint::constraint_force(self)
    }
    fn constraint_torque(&self) -> Real {
        MotorJoint::constraint_torque(self)
    }
    fn carry_through_portal(&mut self, rotation: Rot, scale: Real) {
        MotorJoint::carry_through_portal(self, rotation, scale);
    }
    /// The kept impulses, one body's share: the angle row's, then the
    /// point's at the body's current arm.
    #[inline(always)]
    fn warm_rows(&self, w: &mut WarmSide<'_>) {
        w.angle(self.angle.impulse);
        w.point((self.point.frame_a, self.point.frame_b), self.point.impulse);
    }
    /// The angle row (a motor whose target speed is the feedback
    /// `−β C / h`), then the point rows toward the offset, the impulse's
    /// length bounded by the maximum force.
    #[inline(always)]
    fn solve_rows(&mut self, _ctx: &StepContext, _use_bias: bool, s: &mut RowSolve) {
        if s.m.a.inv_inertia + s.m.b.inv_inertia > 0.0 {
            let c = wrap_angle(self.delta_angle + s.sa.dq.relative_angle(s.sb.dq));
            // Ċ + β C / h → 0: a motor row whose target speed is −β C / h.
            let t = Terms::motor(-self.bias_rate * c);
            let bounds = Bounds::symmetric(self.max_angular_impulse);
            s.angle(1.0, self.angle.mass, t, bounds, &mut self.angle.impulse);
        }
        let (r_a, r_b, c) = self.point.arms(&s.sa, &s.sb);
        let t = PointTerms::feedback(self.bias_rate, c);
        s.point(
            r_a,
            r_b,
            t,
            point_bound(&s.m, self.max_linear_impulse),
            &mut self.point.impulse,
        );
    }
}

impl Constraint for MotorJoint {
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        let Some((a, b)) = self
            .base
            .load(ctx, bodies, self.def.base.body_a, self.def.base.body_b)
        else {
            return;
        };
        let q_a = a.sim.transform.q;
        let q_b = b.sim.transform.q;
        self.point.frame_a = q_a.rotate(self.def.target_anchor_a() - a.sim.local_center);
        self.point.frame_b = q_b.rotate(self.def.base.local_frame_b.anchor - b.sim.local_center);
        self.point.delta_center = b.sim.center - a.sim.center;
        self.delta_angle = wrap_angle(
            q_a.relative_angle(q_b) - self.def.base.reference_angle() - self.def.angular_offset,
        );
        self.angle.prepare(&self.base.masses);
        self.bias_rate = self.def.correction_factor * ctx.inv_h;
        self.max_linear_impulse = self.def.max_force * ctx.h;
        self.max_angular_impulse = self.def.max_torque * ctx.h;
        if ctx.warm_starting {
            // A lowered force or torque (or a shorter substep) bounds the
            // kept impulses before they are applied again.
            self.point.impulse =
                crate::parts::clamp_length(self.point.impulse, self.max_linear_impulse);
            self.angle.impulse = self
                .angle
                .impulse
                .clamp(-self.max_angular_impulse, self.max_angular_impulse);
        } else {
            self.point.impulse = Vec2::ZERO;
            self.angle.impulse = 0.0;
        }
    }

    fn warm_start(&mut self, _ctx: &StepContext, states: &mut [BodyState]) {
        crate::kind_rows::warm_start_states(self, states);
    }

    fn solve(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        crate::kind_rows::solve_states(self, ctx, states, use_bias);
    }

    fn rows(&self, ctx: &StepContext, bodies: &BodySet) -> ConstraintRows {
        let at = RowsAt::at_points(
            bodies,
            (self.def.base.body_a, self.def.target_anchor_a()),
            (self.def.base.body_b, self.def.base.local_frame_b.anchor),
        );
        let (m, r_a, r_b, c) = (at.m, at.r_a, at.r_b, at.c);
        let softness = Softness {
            bias_rate: self.def.correction_factor * ctx.inv_h,
            ..Softness::RIGID
        };
        let (f, t) = (self.def.max_force * ctx.h, self.def.max_torque * ctx.h);
        let mut out = ConstraintRows::default();
        for (axis, c, impulse) in [
            (Vec2::X, c.x, self.point.impulse.x),
            (Vec2::Y, c.y, self.point.impulse.y),
        ] {
            let mut row = at.point_row(axis, c, softness, impulse);
            (row.lower, row.upper) = (-f, f);
            out.rows.push(row);
        }
        out.rows.push(at.angle_row(
            1.0,
            self.angular_error(bodies),
            softness,
            (-t, t),
            self.angle.impulse,
        ));
        let (k11, k12, k22) = PointPart::effective_mass(&m, r_a, r_b);
        out.blocks.push(Block {
            first_row: 0,
            len: 2,
            k: [[k11, k12, 0.0], [k12, k22, 0.0], [0.0; 3]],
        });
        out.blocks.push(Block {
            first_row: 2,
            len: 1,
            k: [
                [m.a.inv_inertia + m.b.inv_inertia, 0.0, 0.0],
                [0.0; 3],
                [0.0; 3],
            ],
        });
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
        let a = set.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        let b = set.create(&BodyDef::dynamic(Vec2::new(1.0, 0.0))).unwrap();
        (set, a, b)
    }

    #[test]
    fn validate_rejects_bad_values() {
        let (_, a, b) = pair();
        let def = MotorJointDef::new(a, b);
        assert_eq!(def.validate(), Ok(()));
        let nan = def.clone().with_offset(Vec2::new(Real::NAN, 0.0), 0.0);
        assert_eq!(nan.validate(), Err(JointError::NonFinite));
        let nan = def.clone().with_max_torque(Real::NAN);
        assert_eq!(nan.validate(), Err(JointError::NonFinite));
        let inf = def.clone().with_correction_factor(Real::INFINITY);
        assert_eq!(inf.validate(), Err(JointError::NonFinite));
        let negative = def.clone().with_max_torque(-1.0);
        assert_eq!(negative.validate(), Err(JointError::Negative));
        let unbounded = def.clone().with_max_force(Real::INFINITY);
        assert_eq!(unbounded.validate(), Ok(()));
        for cf in [-0.1, 1.1] {
            assert!(matches!(
                def.clone().with_correction_factor(cf).validate(),
                Err(JointError::OutOfBounds {
                    field: "correction_factor",
                    ..
                })
            ));
        }
        let far = def.clone().with_offset(Vec2::new(1e12, 0.0), 0.0);
        assert!(matches!(
            far.validate(),
            Err(JointError::OutOfBounds {
                field: "linear_offset",
                ..
            })
        ));
        assert_eq!(
            MotorJointDef::new(a, a).validate(),
            Err(JointError::SameBody)
        );
    }

    #[test]
    fn the_force_stays_within_max_force() {
        let (set, a, b) = pair();
        let settings = SolverSettings::default();
        let ctx = settings.context(1.0 / 60.0, Vec2::ZERO);
        // 1 m from its target, a 10 N drive: the impulse saturates.
        let mut joint = MotorJoint::new(
            MotorJointDef::new(a, b)
                .with_max_force(10.0)
                .with_correction_factor(1.0),
        );
        let mut set = set;
        joint.prepare(&ctx, &set);
        for _ in 0..4 {
            joint.solve(&ctx, &mut set.states, true);
        }
        let force = joint.constraint_force();
        assert!((force.length() - 10.0).abs() < 1e-3, "{force:?}");
        assert!(force.x < 0.0, "pulls b back toward a: {force:?}");
        let rows = joint.rows(&ctx, &set);
        assert_eq!(rows.rows.len(), joint.row_count());
        assert_eq!(rows.rows[0].c, 1.0);
    }
}
