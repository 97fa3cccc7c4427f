//! The joint family: one definition enum at the API boundary, one solver
//! form the solver iterates, and the stages every kind shares.
//!
//! ```text
//!  user                      world (JointSet)              solver
//!  ─────────────────────     ───────────────────────       ───────────────────────────────────
//!  JointDef::Revolute(d) ──▶ Joint::Revolute(j)  ──▶  prepare       each joint (kind's rows)
//!  (validated, typed error)  one Vec<Joint>,           colours       JointColours (keys from JointBase)
//!                            dense, swap-remove        warm start    Joint::warm_start_side, per body
//!                                                      solve, relax  Joint::solve_pair, colour by colour
//!                                                      late solve    JointForest (Joint::tree_rows)
//!                                                      (all driven by joint_solver::JointBatch)
//! ```
//!
//! | kind        | file            | rows                                          | rows the tree solves |
//! |-------------|-----------------|-----------------------------------------------|----------------------|
//! | `Revolute`  | `revolute.rs`   | point (2), spring, motor, lower, upper (1 each) | point (2)          |
//! | `Weld`      | `weld.rs`       | point (2), angle (1)                          | point + angle (3) when rigid, else none |
//!
//! Everything the solver needs from a joint that is not its own rows is in
//! [`JointBase`]: the state indices, the masses loaded at prepare, whether
//! it is enabled, resting or part of a tree. The colouring, the tree solve
//! and the world read joints only through [`Joint`]'s methods, so they
//! never name a kind.
//!
//! **Adding a kind** is one file in this crate (its definition with
//! `validate`, its solver form with `prepare`, `warm_start_side`,
//! `solve_pair`, `rows` and read-backs, and a `base: JointBase` field) plus
//! one variant in [`JointDef`], [`Joint`] and [`JointKind`] and the arms of
//! the matches below. The weld joint touched, besides `weld.rs`: this file,
//! `lib.rs` (module, re-export, kind table), the world's `joints.rs`
//! (`JointSet::weld`), `world/joints.rs` (`World::weld_joint`,
//! `create_weld_joint`) and `world/mod.rs` (its import), and the facade's
//! `src/lib.rs` (re-export, prelude). Nothing in the solver, the colouring or the tree
//! changes; a kind whose rows the tree cannot take (no point part, or
//! soft) returns `None` from `Joint::tree_rows` and the tree solve leaves
//! its component iterative. A kind the tree takes describes its equality
//! rows there (`TreeRows`: the point part, and the angle row when it
//! holds the relative angle too) and takes back the tree's impulses in
//! `Joint::set_tree_impulses`.

use janus2d_core::body::{BodyHandle, BodySet, BodyState};
use janus2d_core::constraint::{Constraint, ConstraintRows, StepContext};
use janus2d_core::math::{Real, Rot, Vec2};

use crate::JointError;
use crate::joint_base::JointBase;
use crate::parts::{BOTH, PairOf, PairStates, PointPart};
use crate::revolute::{RevoluteJoint, RevoluteJointDef};
use crate::weld::{WeldJoint, WeldJointDef};

/// The joint kinds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum JointKind {
    /// A pin: two anchors coincide; optional limit, motor and spring.
    Revolute,
    /// A weld: two anchors coincide and the relative angle is held,
    /// rigidly or through springs.
    Weld,
}

/// Everything needed to create a joint of any kind (the API boundary's
/// one type: `World::create_joint` takes it).
///
/// ```
/// use janus2d_constraints::{JointDef, JointKind, RevoluteJointDef};
/// use janus2d_core::{BodyDef, BodySet, Vec2};
/// let mut bodies = BodySet::new();
/// let a = bodies.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// let b = bodies.create(&BodyDef::dynamic(Vec2::X)).unwrap();
/// let def: JointDef = RevoluteJointDef::new(a, b, Vec2::X, Vec2::ZERO).into();
/// assert_eq!(def.kind(), JointKind::Revolute);
/// assert_eq!(def.bodies(), (a, b));
/// assert!(def.validate().is_ok());
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum JointDef {
    /// A revolute joint.
    Revolute(RevoluteJointDef),
    /// A weld joint.
    Weld(WeldJointDef),
}

impl From<RevoluteJointDef> for JointDef {
    fn from(def: RevoluteJointDef) -> Self {
        JointDef::Revolute(def)
    }
}

impl From<WeldJointDef> for JointDef {
    fn from(def: WeldJointDef) -> Self {
        JointDef::Weld(def)
    }
}

impl JointDef {
    /// The kind of joint this defines.
    #[must_use]
    pub fn kind(&self) -> JointKind {
        match self {
            JointDef::Revolute(_) => JointKind::Revolute,
            JointDef::Weld(_) => JointKind::Weld,
        }
    }

    /// The two bodies `(a, b)`.
    #[must_use]
    pub fn bodies(&self) -> (BodyHandle, BodyHandle) {
        match self {
            JointDef::Revolute(d) => (d.body_a, d.body_b),
            JointDef::Weld(d) => (d.body_a, d.body_b),
        }
    }

    /// Whether the two bodies collide with each other.
    #[must_use]
    pub fn collide_connected(&self) -> bool {
        match self {
            JointDef::Revolute(d) => d.collide_connected,
            JointDef::Weld(d) => d.collide_connected,
        }
    }

    /// Checks the definition's own values (not the handles).
    pub fn validate(&self) -> Result<(), JointError> {
        match self {
            JointDef::Revolute(d) => d.validate(),
            JointDef::Weld(d) => d.validate(),
        }
    }
}

/// A joint in solver form: one variant per kind.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Joint {
    /// A revolute joint.
    Revolute(RevoluteJoint),
    /// A weld joint.
    Weld(WeldJoint),
}

impl From<RevoluteJoint> for Joint {
    fn from(j: RevoluteJoint) -> Self {
        Joint::Revolute(j)
    }
}

impl From<WeldJoint> for Joint {
    fn from(j: WeldJoint) -> Self {
        Joint::Weld(j)
    }
}

impl Joint {
    /// A joint from a definition (validate it first).
    #[must_use]
    pub fn new(def: JointDef) -> Self {
        match def {
            JointDef::Revolute(d) => Joint::Revolute(RevoluteJoint::new(d)),
            JointDef::Weld(d) => Joint::Weld(WeldJoint::new(d)),
        }
    }

    /// Its kind.
    #[must_use]
    pub fn kind(&self) -> JointKind {
        match self {
            Joint::Revolute(_) => JointKind::Revolute,
            Joint::Weld(_) => JointKind::Weld,
        }
    }

    /// Its definition as it stands (limits, motor and spring as last set).
    #[must_use]
    pub fn def(&self) -> JointDef {
        match self {
            Joint::Revolute(j) => JointDef::Revolute(j.def.clone()),
            Joint::Weld(j) => JointDef::Weld(j.def.clone()),
        }
    }

    /// The revolute joint, if it is one.
    #[must_use]
    pub fn as_revolute(&self) -> Option<&RevoluteJoint> {
        match self {
            Joint::Revolute(j) => Some(j),
            _ => None,
        }
    }

    /// The revolute joint, mutable, if it is one.
    pub fn as_revolute_mut(&mut self) -> Option<&mut RevoluteJoint> {
        match self {
            Joint::Revolute(j) => Some(j),
            _ => None,
        }
    }

    /// The weld joint, if it is one.
    #[must_use]
    pub fn as_weld(&self) -> Option<&WeldJoint> {
        match self {
            Joint::Weld(j) => Some(j),
            _ => None,
        }
    }

    /// The common solver data.
    #[inline(always)]
    #[must_use]
    pub fn base(&self) -> &JointBase {
        match self {
            Joint::Revolute(j) => &j.base,
            Joint::Weld(j) => &j.base,
        }
    }

    #[inline(always)]
    pub(crate) fn base_mut(&mut self) -> &mut JointBase {
        match self {
            Joint::Revolute(j) => &mut j.base,
            Joint::Weld(j) => &mut j.base,
        }
    }

    /// The two bodies `(a, b)`.
    #[must_use]
    pub fn bodies(&self) -> (BodyHandle, BodyHandle) {
        match self {
            Joint::Revolute(j) => (j.def.body_a, j.def.body_b),
            Joint::Weld(j) => (j.def.body_a, j.def.body_b),
        }
    }

    /// Whether its bodies collide with each other.
    #[must_use]
    pub fn collide_connected(&self) -> bool {
        match self {
            Joint::Revolute(j) => j.def.collide_connected,
            Joint::Weld(j) => j.def.collide_connected,
        }
    }

    /// The local anchors on a and b (in each body's frame), m.
    #[must_use]
    pub fn local_anchors(&self) -> (Vec2, Vec2) {
        match self {
            Joint::Revolute(j) => (j.def.local_anchor_a, j.def.local_anchor_b),
            Joint::Weld(j) => (j.def.local_anchor_a, j.def.local_anchor_b),
        }
    }

    /// The local anchor on `body` (`None` when `body` is neither end).
    #[must_use]
    pub fn local_anchor_on(&self, body: BodyHandle) -> Option<Vec2> {
        let (a, b) = self.bodies();
        let (anchor_a, anchor_b) = self.local_anchors();
        if a == body {
            Some(anchor_a)
        } else if b == body {
            Some(anchor_b)
        } else {
            None
        }
    }

    /// The body at the other end from `body` (`None` when `body` is
    /// neither end).
    #[must_use]
    pub fn other_body(&self, body: BodyHandle) -> Option<BodyHandle> {
        let (a, b) = self.bodies();
        if a == body {
            Some(b)
        } else if b == body {
            Some(a)
        } else {
            None
        }
    }

    /// False when the joint is disabled.
    #[inline(always)]
    #[must_use]
    pub fn is_enabled(&self) -> bool {
        self.base().enabled
    }

    /// Enables or disables the joint.
    pub fn set_enabled(&mut self, on: bool) {
        self.base_mut().enabled = on;
    }

    /// True when the last step solved its equality rows directly (it is
    /// part of a tree of joints, see [`crate::joint_tree`]).
    #[must_use]
    pub fn in_tree(&self) -> bool {
        self.base().in_tree
    }

    /// A motor of nonzero torque drives the joint's bodies (the light
    /// clusters leave such bodies out).
    #[must_use]
    pub fn is_driven(&self) -> bool {
        match self {
            Joint::Revolute(j) => j.def.enable_motor && j.def.max_motor_torque > 0.0,
            Joint::Weld(_) => false,
        }
    }

    /// Rows this joint adds to the solver when enabled.
    #[must_use]
    pub fn row_count(&self) -> usize {
        match self {
            Joint::Revolute(j) => j.row_count(),
            Joint::Weld(j) => j.row_count(),
        }
    }

    /// Rows of this joint the tree solve takes when it is in a tree.
    #[must_use]
    pub fn tree_row_count(&self) -> usize {
        self.tree_rows().map_or(0, |r| r.count())
    }

    /// Force the joint applied to body b over the last solved step, N.
    #[must_use]
    pub fn constraint_force(&self) -> Vec2 {
        match self {
            Joint::Revolute(j) => j.constraint_force(),
            Joint::Weld(j) => j.constraint_force(),
        }
    }

    /// Torque the joint applied to body b over the last solved step, N·m.
    #[must_use]
    pub fn constraint_torque(&self) -> Real {
        match self {
            Joint::Revolute(j) => j.constraint_torque(),
            Joint::Weld(j) => j.constraint_torque(),
        }
    }

    /// The world anchors on a and b.
    #[must_use]
    pub fn world_anchors(&self, bodies: &BodySet) -> (Vec2, Vec2) {
        match self {
            Joint::Revolute(j) => j.world_anchors(bodies),
            Joint::Weld(j) => j.world_anchors(bodies),
        }
    }

    /// Distance between the two world anchors, m.
    #[must_use]
    pub fn gap(&self, bodies: &BodySet) -> Real {
        let (pa, pb) = self.world_anchors(bodies);
        (pb - pa).length()
    }

    /// Carries the accumulated impulses through a portal when both ends
    /// move to the other side (see [`RevoluteJoint::carry_impulses`]).
    pub fn carry_impulses(&mut self, rotation: Rot, scale: Real) {
        match self {
            Joint::Revolute(j) => j.carry_impulses(rotation, scale),
            Joint::Weld(j) => j.carry_impulses(rotation, scale),
        }
    }

    /// Moves the end on body `from` to body `to` with the local anchor
    /// `anchor` in `to`'s frame; false when `from` is not one of its ends.
    pub fn repoint(&mut self, from: BodyHandle, to: BodyHandle, anchor: Vec2) -> bool {
        let (body_a, anchor_a, body_b, anchor_b) = match self {
            Joint::Revolute(j) => (
                &mut j.def.body_a,
                &mut j.def.local_anchor_a,
                &mut j.def.body_b,
                &mut j.def.local_anchor_b,
            ),
            Joint::Weld(j) => (
                &mut j.def.body_a,
                &mut j.def.local_anchor_a,
                &mut j.def.body_b,
                &mut j.def.local_anchor_b,
            ),
        };
        if *body_a == from {
            *body_a = to;
            *anchor_a = anchor;
        } else if *body_b == from {
            *body_b = to;
            *anchor_b = anchor;
        } else {
            return false;
        }
        true
    }

    /// The equality rows the tree solve takes over when the joint is in a
    /// tree (`None`: the tree cannot take the joint, and a component
    /// holding it is solved iteratively).
    #[inline(always)]
    pub(crate) fn tree_rows(&self) -> Option<TreeRows<'_>> {
        match self {
            Joint::Revolute(j) => Some(TreeRows {
                point: &j.point,
                angle: None,
            }),
            Joint::Weld(j) => j.def.is_rigid().then_some(TreeRows {
                point: &j.point,
                angle: Some(TreeAngle {
                    delta_angle: j.delta_angle,
                    impulse: j.angle.impulse,
                }),
            }),
        }
    }

    /// The point part, mutable (the unit tests set impulses and arms
    /// through it).
    #[cfg(test)]
    pub(crate) fn tree_point_mut(&mut self) -> Option<&mut PointPart> {
        match self {
            Joint::Revolute(j) => Some(&mut j.point),
            Joint::Weld(j) => Some(&mut j.point),
        }
    }

    /// Takes back the impulses of the tree's solve of its rows: the point
    /// impulse, and the angle impulse when [`Joint::tree_rows`] has an
    /// angle row (ignored otherwise).
    #[inline(always)]
    pub(crate) fn set_tree_impulses(&mut self, point: Vec2, angle: Real) {
        match self {
            Joint::Revolute(j) => j.point.impulse = point,
            Joint::Weld(j) => {
                j.point.impulse = point;
                j.angle.impulse = angle;
            }
        }
    }

    /// True when the joint has rows for the Gauss–Seidel pass this step:
    /// every row when it is outside a tree, its other rows (springs,
    /// motors, limits) when it is in one.
    #[inline(always)]
    pub(crate) fn has_iterative_rows(&self) -> bool {
        match self {
            Joint::Revolute(j) => !j.base.in_tree || j.has_angle_rows(),
            Joint::Weld(j) => !j.base.in_tree,
        }
    }

    /// The warm start's share on one body (`side_b`: body b, else a).
    #[inline(always)]
    pub(crate) fn warm_start_side(&self, st: &mut BodyState, side_b: bool) {
        match self {
            Joint::Revolute(j) => j.warm_start_side(st, side_b),
            Joint::Weld(j) => j.warm_start_side(st, side_b),
        }
    }

    /// One velocity iteration of the joint's Gauss–Seidel rows.
    #[inline(always)]
    pub(crate) fn solve_pair<P: PairStates>(
        &mut self,
        ctx: &StepContext,
        pair: &mut P,
        use_bias: bool,
    ) {
        match self {
            Joint::Revolute(j) => j.solve_pair(ctx, pair, use_bias),
            Joint::Weld(j) => j.solve_pair(ctx, pair, use_bias),
        }
    }
}

impl Constraint for Joint {
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        match self {
            Joint::Revolute(j) => j.prepare(ctx, bodies),
            Joint::Weld(j) => j.prepare(ctx, bodies),
        }
    }

    fn warm_start(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        match self {
            Joint::Revolute(j) => j.warm_start(ctx, states),
            Joint::Weld(j) => j.warm_start(ctx, states),
        }
    }

    fn solve(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        let (a, b) = (self.base().state_a, self.base().state_b);
        let mut pair = PairOf::new(states, a, b, BOTH);
        self.solve_pair(ctx, &mut pair, use_bias);
    }

    fn rows(&self, ctx: &StepContext, bodies: &BodySet) -> ConstraintRows {
        match self {
            Joint::Revolute(j) => j.rows(ctx, bodies),
            Joint::Weld(j) => j.rows(ctx, bodies),
        }
    }

    fn is_enabled(&self) -> bool {
        self.base().enabled
    }
}

/// A joint's equality rows as the tree solve takes them: the point rows,
/// and for a joint that also holds the relative angle, the angle row
/// (`C_θ = θ_b − θ_a − θ_ref`, `J_θ = [0 0 −1 │ 0 0 1]`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct TreeRows<'a> {
    /// The point part (arms, centre offset, impulse).
    pub(crate) point: &'a PointPart,
    /// The angle row, for a 3-row joint.
    pub(crate) angle: Option<TreeAngle>,
}

impl TreeRows<'_> {
    /// Number of rows: 2 (point) or 3 (point and angle).
    #[inline(always)]
    pub(crate) fn count(&self) -> usize {
        2 + usize::from(self.angle.is_some())
    }
}

/// The angle row of a joint's tree rows.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TreeAngle {
    /// `C_θ` at the start of the step, rad.
    pub(crate) delta_angle: Real,
    /// Accumulated impulse, N·m·s.
    pub(crate) impulse: Real,
}
