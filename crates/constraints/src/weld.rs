//! The weld joint: two bodies held at a shared point and a fixed relative
//! angle, rigidly or through a linear and an angular spring.
//!
//! # Derivation
//!
//! Bodies `a` and `b` with centres `x_a`, `x_b`, angles `θ_a`, `θ_b`, and
//! anchors `r_a = R(θ_a)(l_a − c_a)`, `r_b = R(θ_b)(l_b − c_b)` measured from
//! the centres of mass.
//!
//! **Point (2 rows)**, as the revolute joint's:
//! `C_p = (x_b + r_b) − (x_a + r_a)`, `J_p = [ −I  −perp(r_a)   I  perp(r_b) ]`.
//!
//! **Angle (1 row).** `C_θ = θ_b − θ_a − θ_ref`, `J_θ = [ 0 0 −1 │ 0 0 1 ]`,
//! `K_θ = i_a⁻¹ + i_b⁻¹`.
//!
//! The three rows together (`J = [J_p; J_θ]`) have the 3×3 effective mass
//!
//! ```text
//! K = J M⁻¹ Jᵀ = [ m + i_a r_a.y² + i_b r_b.y²      −i_a r_a.x r_a.y − i_b r_b.x r_b.y    −i_a r_a.y − i_b r_b.y ]
//!                [ ·                                 m + i_a r_a.x² + i_b r_b.x²          i_a r_a.x + i_b r_b.x  ]
//!                [ ·                                 ·                                    i_a + i_b              ]
//! ```
//!
//! with `m = m_a⁻¹ + m_b⁻¹`, `i = I⁻¹`. The Gauss–Seidel pass solves the
//! angle row, then the point rows as a 2×2 block (the coupling `K₀₂`, `K₁₂`
//! is left to the iterations); the tree solve of a rigid weld takes all
//! three rows at once with the full `K` ([`crate::joint_tree`]).
//!
//! **Softness.** A zero `linear_hertz` (`angular_hertz`) makes the point
//! (angle) rows rigid: the world's joint softness, built on the heavier
//! body's mass (inertia) like the revolute joint's point rows,
//! `ρ = min((w_a + w_b) / min(w_a, w_b), ρ_max)` with `w` the inverse mass
//! (inertia), `ρ_max` against a body that does not move (turn). A nonzero
//! one makes a spring `Softness::new(hertz, damping_ratio, h)`, applied in
//! the relax pass too (a spring is a force, not a position correction), its
//! bias not capped. Only a weld rigid on both is solved by the tree.

use janus2d_core::body::{BodyHandle, BodySet, BodyState};
use janus2d_core::constraint::{Block, Constraint, ConstraintRows, StepContext};
use janus2d_core::math::{Real, Vec2};
use janus2d_core::softness::Softness;

use crate::joint_base::{JointBase, RowsAt};
use crate::joint_def::{JointDefBase, KindDef};
use crate::joint_rows::{Bounds, PointTerms, RowSolve, Terms, WarmSide, point_bound};
use crate::kind_rows::{KindRows, TreeAngle, TreeRows};
use crate::parts::{AnglePart, PairMass, PointPart, angular_correction_cap};
use crate::{JointError, check_spring};

/// Everything needed to create a weld joint.
///
/// ```
/// use janus2d_constraints::WeldJointDef;
/// use janus2d_core::{BodyDef, BodySet, Vec2};
/// let mut bodies = BodySet::new();
/// let a = bodies.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// let b = bodies.create(&BodyDef::dynamic(Vec2::X)).unwrap();
/// let def = WeldJointDef::new(a, b, Vec2::new(0.5, 0.0), Vec2::new(-0.5, 0.0));
/// assert!(def.is_rigid());
/// assert!(def.validate().is_ok());
/// assert!(!def.with_stiffness(0.0, 0.0, 2.0, 0.1).is_rigid());
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct WeldJointDef {
    /// Bodies, frames (the anchors; the held angle `θ_b − θ_a` is
    /// `φ_a − φ_b`) and shared settings.
    pub base: JointDefBase,
    /// Stiffness of the point rows, Hz (0: rigid).
    pub linear_hertz: Real,
    /// Damping ratio of the point rows (dimensionless; unused when rigid).
    pub linear_damping_ratio: Real,
    /// Stiffness of the angle row, Hz (0: rigid).
    pub angular_hertz: Real,
    /// Damping ratio of the angle row (dimensionless; unused when rigid).
    pub angular_damping_ratio: Real,
}

impl Default for WeldJointDef {
    /// A rigid weld between two placeholder bodies
    /// ([`JointDefBase::default`]: set `base.body_a` and `base.body_b`
    /// before use; `validate` refuses the placeholders as one body).
    fn default() -> Self {
        Self::from_base(JointDefBase::default())
    }
}

impl WeldJointDef {
    /// A rigid weld between two bodies at the given local anchors, holding
    /// the relative angle they have at zero (`reference_angle` 0).
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

    /// A rigid weld on a shared base (frames, thresholds, softness).
    pub fn from_base(base: JointDefBase) -> Self {
        WeldJointDef {
            base,
            linear_hertz: 0.0,
            linear_damping_ratio: 0.0,
            angular_hertz: 0.0,
            angular_damping_ratio: 0.0,
        }
    }

    /// Sets the springs (builder style): stiffness in Hz (0: rigid) and
    /// damping ratio of the point rows, then of the angle row.
    pub fn with_stiffness(
        mut self,
        linear_hertz: Real,
        linear_damping_ratio: Real,
        angular_hertz: Real,
        angular_damping_ratio: Real,
    ) -> Self {
        self.linear_hertz = linear_hertz;
        self.linear_damping_ratio = linear_damping_ratio;
        self.angular_hertz = angular_hertz;
        self.angular_damping_ratio = angular_damping_ratio;
        self
    }

    /// Sets the held angle `θ_b − θ_a`, rad (builder style): frame a's
    /// angle, frame b's set to 0.
    pub fn with_reference_angle(mut self, angle: Real) -> Self {
        self.base.local_frame_a.angle = angle;
        self.base.local_frame_b.angle = 0.0;
        self
    }

    /// True when both the point rows and the angle row are rigid (zero
    /// hertz, and no constraint softness of its own): the joint tree can
    /// solve it directly.
    #[must_use]
    pub fn is_rigid(&self) -> bool {
        self.linear_hertz == 0.0 && self.angular_hertz == 0.0 && self.base.constraint_hertz == 0.0
    }

    /// Checks the definition's own values (not the handles).
    pub fn validate(&self) -> Result<(), JointError> {
        self.base.validate()?;
        let finite = self.linear_hertz.is_finite()
            && self.linear_damping_ratio.is_finite()
            && self.angular_hertz.is_finite()
            && self.angular_damping_ratio.is_finite();
        if !finite {
            return Err(JointError::NonFinite);
        }
        if self.linear_hertz < 0.0
            || self.linear_damping_ratio < 0.0
            || self.angular_hertz < 0.0
            || self.angular_damping_ratio < 0.0
        {
            return Err(JointError::Negative);
        }
        check_spring(self.linear_hertz, self.linear_damping_ratio)?;
        check_spring(self.angular_hertz, self.angular_damping_ratio)
    }
}

impl KindDef for WeldJointDef {
    fn base(&self) -> &JointDefBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointDefBase {
        &mut self.base
    }
    fn validate(&self) -> Result<(), JointError> {
        WeldJointDef::validate(self)
    }
}

/// A weld joint in solver form.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(C)]
pub struct WeldJoint {
    /// State indices, masses and switches the solver reads.
    pub(crate) base: JointBase,
    /// The definition it was made from.
    pub(crate) def: Box<WeldJointDef>,
    /// The point rows.
    pub(crate) point: PointPart,
    /// The angle row.
    pub(crate) angle: AnglePart,
    /// `C_θ = θ_b − θ_a − θ_ref` at the start of the step, rad.
    pub(crate) delta_angle: Real,
    /// Softness of the point rows for this step.
    linear_softness: Softness,
    /// Softness of the angle row for this step.
    angular_softness: Softness,
}

/// The softness of the weld's point rows and angle row for a step (see
/// the module docs), used by the solve and reported by `rows()`.
fn softnesses(def: &WeldJointDef, ctx: &StepContext, m: &PairMass) -> (Softness, Softness) {
    let linear = if def.linear_hertz == 0.0 {
        def.base.rigid_softness(ctx, m.a.inv_mass, m.b.inv_mass)
    } else {
        Softness::new(def.linear_hertz, def.linear_damping_ratio, ctx.h)
    };
    let angular = if def.angular_hertz == 0.0 {
        def.base
            .rigid_softness(ctx, m.a.inv_inertia, m.b.inv_inertia)
    } else {
        Softness::new(def.angular_hertz, def.angular_damping_ratio, ctx.h)
    };
    (linear, angular)
}

impl WeldJoint {
    /// A joint from a definition (validate it first).
    pub fn new(def: WeldJointDef) -> Self {
        WeldJoint {
            def: Box::new(def),
            base: JointBase::default(),
            point: PointPart::default(),
            angle: AnglePart::default(),
            delta_angle: 0.0,
            linear_softness: Softness::RIGID,
            angular_softness: Softness::RIGID,
        }
    }

    /// Rows this joint adds to the solver when enabled: two point rows and
    /// one angle row.
    #[must_use]
    pub fn row_count(&self) -> usize {
        3
    }

    /// Carries the accumulated impulses through a portal when both ends
    /// move to the other side (as [`crate::RevoluteJoint::carry_through_portal`]:
    /// the point impulse turns and scales, the angle impulse is kept).
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

    /// The angle error `θ_b − θ_a − θ_ref`, rad (wrapped to `[−π, π]`).
    pub fn angle(&self, bodies: &BodySet) -> Real {
        crate::joint_base::relative_angle(
            bodies,
            self.def.base.body_a,
            self.def.base.body_b,
            self.def.base.reference_angle(),
        )
    }

    /// True when the last step solved its rows directly (the joint is part
    /// of a tree of joints, see [`crate::joint_tree`]).
    pub fn in_tree(&self) -> bool {
        self.base.in_tree
    }

    /// False when the joint is disabled (skipped by the solver).
    #[must_use]
    pub fn is_enabled(&self) -> bool {
        self.base.enabled
    }

    /// Point impulse of one substep of the last solved step, N·s.
    pub fn linear_impulse(&self) -> Vec2 {
        self.point.impulse
    }

    /// Angle impulse of one substep of the last solved step, N·m·s.
    pub fn angular_impulse(&self) -> Real {
        self.angle.impulse
    }

    /// Force the joint applies to body b over the last solved step, N
    /// (body a gets the opposite).
    #[must_use]
    pub fn constraint_force(&self) -> Vec2 {
        self.point.impulse * self.base.inv_h
    }

    /// Torque the angle row applies to body b over the last solved step,
    /// N·m (body a gets the opposite).
    #[must_use]
    pub fn constraint_torque(&self) -> Real {
        self.angle.impulse * self.base.inv_h
    }

    /// `C_θ` from the states' rotation deltas.
    fn current_angle(&self, sa: &BodyState, sb: &BodyState) -> Real {
        janus2d_core::math::wrap_angle(self.delta_angle + sa.dq.relative_angle(sb.dq))
    }
}

impl KindRows for WeldJoint {
    fn base(&self) -> &JointBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointBase {
        &mut self.base
    }
    fn row_count(&self) -> usize {
        WeldJoint::row_count(self)
    }
    fn constraint_force(&self) -> Vec2 {
        WeldJoint::constraint_force(self)
    }
    fn constraint_torque(&self) -> Real {
        WeldJoint::constraint_torque(self)
    }
    fn carry_through_portal(&mut self, rotation: janus2d_core::math::Rot, scale: Real) {
        WeldJoint::carry_through_portal(self, rotation, scale);
    }
    /// The kept impulses, one body's share: the angle row's, then the
    /// point's at the body's current arm.
    #[inline(always)]
    fn warm_rows(&self, w: &mut WarmSide<'_>) {
        w.angle(self.angle.impulse);
        w.point((self.point.frame_a, self.point.frame_b), self.point.impulse);
    }
    /// The angle row, then the point rows (a tree joint's rows are all
    /// the tree's: it has none here).
    #[inline(always)]
    fn solve_rows(&mut self, ctx: &StepContext, use_bias: bool, s: &mut RowSolve) {
        let angular_spring = self.def.angular_hertz > 0.0;
        if s.m.a.inv_inertia + s.m.b.inv_inertia > 0.0 {
            let c = self.current_angle(&s.sa, &s.sb);
            // A spring acts in the relax pass too; a rigid row relaxes
            // without position feedback, and its feedback speed is capped
            // (a spring's is its force).
            let softness = if use_bias || angular_spring {
                self.angular_softness
            } else {
                Softness::RIGID
            };
            let max_bias = if angular_spring {
                Real::INFINITY
            } else {
                angular_correction_cap(ctx.joint_max_correction_speed)
            };
            let t = Terms::soft(softness, c, max_bias);
            s.angle(
                1.0,
                self.angle.mass,
                t,
                Bounds::Free,
                &mut self.angle.impulse,
            );
        }
        let (r_a, r_b, c) = self.point.arms(&s.sa, &s.sb);
        let t = if self.def.linear_hertz > 0.0 {
            // A spring: always on, its bias not capped.
            PointTerms::equality(self.linear_softness, c, Real::MAX, true)
        } else {
            PointTerms::equality(
                self.linear_softness,
                c,
                ctx.joint_max_correction_speed,
                use_bias,
            )
        };
        s.point_equality(r_a, r_b, t, &mut self.point.impulse);
    }
    #[inline(always)]
    fn tree_rows(&self) -> Option<TreeRows<'_>> {
        self.def.is_rigid().then_some(TreeRows::Point {
            point: &self.point,
            angle: Some(TreeAngle {
                delta_angle: self.delta_angle,
                impulse: self.angle.impulse,
            }),
        })
    }
    #[inline(always)]
    fn set_tree_impulses(&mut self, impulses: [Real; 3]) {
        self.point.impulse = Vec2::new(impulses[0], impulses[1]);
        self.angle.impulse = impulses[2];
    }
    #[cfg(test)]
    fn tree_point_mut(&mut self) -> Option<&mut PointPart> {
        Some(&mut self.point)
    }
}

impl Constraint for WeldJoint {
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
        self.delta_angle = janus2d_core::math::wrap_angle(
            q_a.relative_angle(q_b) - self.def.base.reference_angle(),
        );
        let m = self.base.masses;
        self.angle.prepare(&m);
        (self.linear_softness, self.angular_softness) = softnesses(&self.def, ctx, &m);
        if !ctx.warm_starting {
            self.point.impulse = Vec2::ZERO;
            self.angle.impulse = 0.0;
        }
        // The point block's once-a-step bound (`RowSolve::point_equality`).
        self.point.hold_within(point_bound(&m, Real::INFINITY));
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
        let (iia, iib) = (m.a.inv_inertia, m.b.inv_inertia);
        // A tree joint's three rows are solved directly, at its softness.
        let (linear_softness, angular_softness) = if self.base.in_tree {
            (ctx.direct_joint_softness, ctx.direct_joint_softness)
        } else {
            softnesses(&self.def, ctx, &m)
        };
        let mut out = ConstraintRows::default();
        out.rows
            .push(at.point_row(Vec2::X, c.x, linear_softness, self.point.impulse.x));
        out.rows
            .push(at.point_row(Vec2::Y, c.y, linear_softness, self.point.impulse.y));
        out.rows.push(at.angle_row(
            1.0,
            self.angle(bodies),
            angular_softness,
            (Real::NEG_INFINITY, Real::INFINITY),
            self.angle.impulse,
        ));
        let (k11, k12, k22) = PointPart::effective_mass(&m, r_a, r_b);
        let k33 = iia + iib;
        if self.base.in_tree {
            // One 3×3 block: the tree solves the rows together.
            let k13 = -iia * r_a.y - iib * r_b.y;
            let k23 = iia * r_a.x + iib * r_b.x;
            out.blocks.push(Block {
                first_row: 0,
                len: 3,
                k: [[k11, k12, k13], [k12, k22, k23], [k13, k23, k33]],
            });
        } else {
            // The Gauss–Seidel pass solves the point block and the angle
            // row one after the other.
            out.blocks.push(Block {
                first_row: 0,
                len: 2,
                k: [[k11, k12, 0.0], [k12, k22, 0.0], [0.0; 3]],
            });
            out.blocks.push(Block {
                first_row: 2,
                len: 1,
                k: [[k33, 0.0, 0.0], [0.0; 3], [0.0; 3]],
            });
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
        let a = set.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        let b = set.create(&BodyDef::dynamic(Vec2::new(1.0, 0.0))).unwrap();
        (set, a, b)
    }

    #[test]
    fn validate_rejects_bad_values() {
        let (_, a, b) = pair();
        let def = WeldJointDef::new(a, b, Vec2::ZERO, Vec2::ZERO);
        assert_eq!(def.validate(), Ok(()));
        let mut nan = def.clone();
        nan.base.local_frame_b.anchor.x = Real::NAN;
        assert_eq!(nan.validate(), Err(JointError::NonFinite));
        let negative = def.clone().with_stiffness(-1.0, 0.0, 0.0, 0.0);
        assert_eq!(negative.validate(), Err(JointError::Negative));
        let same = WeldJointDef::new(a, a, Vec2::ZERO, Vec2::ZERO);
        assert_eq!(same.validate(), Err(JointError::SameBody));
        let far = WeldJointDef::new(a, b, Vec2::new(1e12, 0.0), Vec2::ZERO);
        assert!(matches!(
            far.validate(),
            Err(JointError::OutOfBounds { .. })
        ));
    }

    /// The point block's once-a-step bound, as the revolute joint's: a
    /// kept impulse past `m_eff · ROW_SPEED_BOUND` (a 2 kg body welded to
    /// the ground: bound 800,000 N·s) is held at the bound at prepare, its
    /// direction kept; one inside it is kept bit for bit.
    #[test]
    fn a_kept_point_impulse_past_the_row_bound_is_held_at_prepare() {
        let mut set = BodySet::new();
        let a = set.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        let b = set
            .create(&BodyDef::dynamic(Vec2::new(1.0, 0.0)).with_mass(2.0, 0.5))
            .unwrap();
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
        let mut joint = WeldJoint::new(WeldJointDef::new(a, b, Vec2::ZERO, Vec2::new(-1.0, 0.0)));
        let bound = crate::parts::ROW_SPEED_BOUND * 2.0;
        joint.point.impulse = Vec2::new(-6.0e5, 8.0e5) * 2.0;
        joint.prepare(&ctx, &set);
        let held = joint.point.impulse;
        assert!((held.length() - bound).abs() <= 1e-6 * bound, "{held:?}");
        assert!((held.x / held.y + 0.75).abs() < 1e-6, "{held:?}");
        let inside = Vec2::new(2.0e3, 1.0);
        joint.point.impulse = inside;
        joint.prepare(&ctx, &set);
        assert_eq!(joint.point.impulse, inside);
    }

    #[test]
    fn rows_report_three_rows_and_the_solve_softness() {
        let (set, a, b) = pair();
        let settings = SolverSettings::default();
        let ctx = settings.context(1.0 / 60.0, Vec2::ZERO);
        let mut joint = WeldJoint::new(WeldJointDef::new(
            a,
            b,
            Vec2::new(0.5, 0.0),
            Vec2::new(-0.5, 0.0),
        ));
        joint.prepare(&ctx, &set);
        let rows = joint.rows(&ctx, &set);
        assert_eq!(rows.rows.len(), joint.row_count());
        for row in &rows.rows[..2] {
            assert_eq!(row.softness, joint.linear_softness);
        }
        assert_eq!(rows.rows[2].softness, joint.angular_softness);
        let lens: Vec<usize> = rows.blocks.iter().map(|b| b.len).collect();
        assert_eq!(lens, vec![2, 1]);
    }
}
