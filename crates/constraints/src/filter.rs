//! The filter joint (Box2D's filter joint): no rows at all; its one effect
//! is its base's `collide_connected = false`, so its two bodies never
//! collide with each other while it exists.
//!
//! It adds nothing to the solver (`row_count` 0; prepare only loads the
//! state indices the colouring reads; warm start and solve do nothing; its
//! force and torque read back 0, so it never reports a joint event), and
//! nothing to the tree solve. A filter joint created with
//! `collide_connected = true` is accepted and does nothing at all.
//!
//! Through a portal it follows its bodies as every joint does; with no
//! impulses, [`FilterJoint::carry_through_portal`] has nothing to carry.

use janus2d_core::body::{BodyHandle, BodySet, BodyState};
use janus2d_core::constraint::{Constraint, ConstraintRows, StepContext};
use janus2d_core::math::{Real, Rot, Vec2};

use crate::JointError;
use crate::joint_base::JointBase;
use crate::joint_def::{JointDefBase, KindDef};
use crate::joint_rows::{RowSolve, WarmSide};
use crate::kind_rows::KindRows;

/// Everything needed to create a filter joint: only the shared base
/// (`collide_connected` false, its default, is what the joint is for).
///
/// ```
/// use janus2d_constraints::FilterJointDef;
/// use janus2d_core::{BodyDef, BodySet, Vec2};
/// let mut bodies = BodySet::new();
/// let a = bodies.create(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
/// let b = bodies.create(&BodyDef::dynamic(Vec2::X)).unwrap();
/// let def = FilterJointDef::new(a, b);
/// assert!(!def.base.collide_connected);
/// assert!(def.validate().is_ok());
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FilterJointDef {
    /// Bodies and shared settings (frames unused but for drawing;
    /// `collide_connected` true makes the joint do nothing).
    pub base: JointDefBase,
}

impl Default for FilterJointDef {
    /// A filter joint between two placeholder bodies
    /// ([`JointDefBase::default`]: set `base.body_a` and `base.body_b`
    /// before use; `validate` refuses the placeholders as one body).
    fn default() -> Self {
        Self::from_base(JointDefBase::default())
    }
}

impl FilterJointDef {
    /// A filter joint between `body_a` and `body_b`: they no longer
    /// collide with each other.
    pub fn new(body_a: BodyHandle, body_b: BodyHandle) -> Self {
        FilterJointDef {
            base: JointDefBase::new(body_a, body_b),
        }
    }

    /// A filter joint on a shared base.
    pub fn from_base(base: JointDefBase) -> Self {
        FilterJointDef { base }
    }

    /// Checks the shared values (the kind has none of its own).
    pub fn validate(&self) -> Result<(), JointError> {
        self.base.validate()
    }
}

impl KindDef for FilterJointDef {
    fn base(&self) -> &JointDefBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointDefBase {
        &mut self.base
    }
    fn validate(&self) -> Result<(), JointError> {
        FilterJointDef::validate(self)
    }
}

/// A filter joint in solver form: no rows.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(C)]
pub struct FilterJoint {
    /// State indices and switches the colouring reads.
    pub(crate) base: JointBase,
    /// The definition it was made from.
    pub(crate) def: Box<FilterJointDef>,
}

impl FilterJoint {
    /// A joint from a definition (validate it first).
    pub fn new(def: FilterJointDef) -> Self {
        FilterJoint {
            def: Box::new(def),
            base: JointBase::default(),
        }
    }

    /// Rows this joint adds to the solver: none.
    #[must_use]
    pub fn row_count(&self) -> usize {
        0
    }

    /// Nothing to carry through a portal (no impulses).
    pub fn carry_through_portal(&mut self, _rotation: Rot, _scale: Real) {}

    /// False when the joint is disabled.
    #[must_use]
    pub fn is_enabled(&self) -> bool {
        self.base.enabled
    }

    /// Always zero, N.
    #[must_use]
    pub fn constraint_force(&self) -> Vec2 {
        Vec2::ZERO
    }

    /// Always zero, N·m.
    #[must_use]
    pub fn constraint_torque(&self) -> Real {
        0.0
    }
}

impl KindRows for FilterJoint {
    fn base(&self) -> &JointBase {
        &self.base
    }
    fn base_mut(&mut self) -> &mut JointBase {
        &mut self.base
    }
    fn row_count(&self) -> usize {
        FilterJoint::row_count(self)
    }
    fn constraint_force(&self) -> Vec2 {
        FilterJoint::constraint_force(self)
    }
    fn constraint_torque(&self) -> Real {
        FilterJoint::constraint_torque(self)
    }
    fn carry_through_portal(&mut self, rotation: Rot, scale: Real) {
        FilterJoint::carry_through_portal(self, rotation, scale);
    }
    #[inline(always)]
    fn warm_rows(&self, _w: &mut WarmSide<'_>) {}
    #[inline(always)]
    fn solve_rows(&mut self, _ctx: &StepContext, _use_bias: bool, _s: &mut RowSolve) {}
}

impl Constraint for FilterJoint {
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        // Only the state indices (the colouring's keys) and `inv_h`.
        let _ = self
            .base
            .load(ctx, bodies, self.def.base.body_a, self.def.base.body_b);
    }

    fn warm_start(&mut self, _ctx: &StepContext, _states: &mut [BodyState]) {}

    fn solve(&mut self, _ctx: &StepContext, _states: &mut [BodyState], _use_bias: bool) {}

    fn rows(&self, _ctx: &StepContext, _bodies: &BodySet) -> ConstraintRows {
        ConstraintRows::default()
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
    fn has_no_rows_and_moves_nothing() {
        let mut set = BodySet::new();
        let a = set
            .create(&BodyDef::dynamic(Vec2::ZERO).with_velocity(Vec2::X))
            .unwrap();
        let b = set.create(&BodyDef::dynamic(Vec2::Y)).unwrap();
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
        let mut joint = crate::Joint::from(FilterJoint::new(FilterJointDef::new(a, b)));
        assert_eq!(joint.def().validate(), Ok(()));
        let before = set.states.clone();
        joint.prepare(&ctx, &set);
        joint.warm_start(&ctx, &mut set.states);
        joint.solve(&ctx, &mut set.states, true);
        assert_eq!(set.states, before);
        assert_eq!(joint.row_count(), 0);
        assert_eq!(joint.tree_row_count(), 0);
        assert!(joint.rows(&ctx, &set).rows.is_empty());
        assert_eq!(joint.constraint_force(), Vec2::ZERO);
        assert_eq!(joint.constraint_torque(), 0.0);
        assert!(!joint.collide_connected());
        assert!(!joint.check_thresholds());
    }
}
