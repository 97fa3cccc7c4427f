//! The joint family: one definition enum at the API boundary, one solver
//! form the solver iterates, and the stages every kind shares.
//!
//! ```text
//!  user                      world (JointSet)              solver
//!  ─────────────────────     ───────────────────────       ───────────────────────────────────
//!  JointDef::Revolute(d) ──▶ Joint::Revolute(j)  ──▶  prepare       each joint (kind's rows)
//!  (validated, typed error)  one Vec<Joint>,           colours       JointColours (keys from JointBase)
//!                            dense, swap-remove        warm start    kind's warm_rows → WarmSide, per body
//!                                                      solve, relax  kind's solve_rows → RowSolve, colour by colour
//!                                                      late solve    JointForest (Joint::tree_rows)
//!                                                      (all driven by joint_solver::JointBatch)
//! ```
//!
//! | kind        | file            | rows                                          | rows the tree solves |
//! |-------------|-----------------|-----------------------------------------------|----------------------|
//! | `Revolute`  | `revolute.rs`   | point (2), spring, motor, lower, upper (1 each) | point (2)          |
//! | `Weld`      | `weld.rs`       | point (2), angle (1)                          | point + angle (3) when rigid, else none |
//! | `Motor`     | `motor.rs`      | linear (2, force-bounded), angular (1, torque-bounded) | none            |
//! | `Filter`    | `filter.rs`     | none (only `collide_connected = false`)       | none                 |
//! | `Prismatic` | `prismatic.rs`  | perpendicular + angle (2×2 block), spring, motor, lower, upper (1 each, along the axis) | none |
//! | `Wheel`     | `wheel.rs`      | perpendicular (1), spring, lower, upper (1 each, along the axis), motor (angular) | none |
//! | `Distance`  | `distance.rs`   | length or spring, motor, lower, upper (1 each, along the line) | none |
//! | `Mouse`     | `mouse.rs`      | point toward the target (2, body b only), angular damping (1) | none |
//!
//! Everything the solver needs from a joint that is not its own rows is in
//! [`JointBase`]: the state indices, the masses loaded at prepare, whether
//! it is enabled, resting or part of a tree. The colouring, the tree solve
//! and the world read joints only through [`Joint`]'s methods, so they
//! never name a kind.
//!
//! **Adding a kind** is one file in this crate plus one line in the
//! `joint_kinds!` list below: the file holds the definition (with
//! `validate`, and `KindDef`'s limits, motor and spring views when it has
//! them) and the solver form, whose `prepare` loads the bodies, whose
//! `solve_rows` hands its rows to `joint_rows::RowSolve` in solve
//! order and whose `warm_rows` hands their kept impulses to
//! `joint_rows::WarmSide`; plus `rows` (the report) and the
//! read-backs. The macro generates the enums, the conversions and every
//! dispatch; the world, the colouring, the warm start, the solve and the
//! tree never name a kind. A kind whose rows the tree cannot take returns
//! `None` from `KindRows::tree_rows` and the tree leaves its component
//! iterative; a kind the tree takes describes its equality rows there
//! (`TreeRows`) and takes back the tree's impulses in
//! `KindRows::set_tree_impulses`.

use janus2d_core::body::{BodyHandle, BodySet, BodyState};
use janus2d_core::constraint::{Constraint, ConstraintRows, StepContext};
use janus2d_core::math::{Real, Rot, Vec2};

use crate::JointError;
use crate::distance::{DistanceJoint, DistanceJointDef};
use crate::filter::{FilterJoint, FilterJointDef};
use crate::joint_base::JointBase;
use crate::joint_def::{JointDefBase, KindDef, LimitsMut, MotorMut, SpringMut};

use crate::kind_rows::{GeneralRows, KindRows, TreeRows};
use crate::motor::{MotorJoint, MotorJointDef};
use crate::mouse::{MouseJoint, MouseJointDef};
#[cfg(test)]
use crate::parts::PointPart;
use crate::parts::{BOTH, PairOf, PairStates};
use crate::prismatic::{PrismaticJoint, PrismaticJointDef};
use crate::revolute::{RevoluteJoint, RevoluteJointDef};
use crate::weld::{WeldJoint, WeldJointDef};
use crate::wheel::{WheelJoint, WheelJointDef};

/// A kind's solver form as the world's typed accessors reach it
/// (`World::joint_of::<PrismaticJoint>(h)`): implemented for every kind.
pub trait JointOfKind: Sized {
    /// The kind.
    const KIND: JointKind;
    /// The kind's definition type.
    type Def: KindDef;
    /// The joint, if it is of this kind.
    fn from_joint(joint: &Joint) -> Option<&Self>;
    /// The joint, mutable, if it is of this kind.
    fn from_joint_mut(joint: &mut Joint) -> Option<&mut Self>;
    /// Its definition as it stands.
    fn def(&self) -> &Self::Def;
}

/// The kind list, written once: each line is `Variant(SolverForm,
/// Definition)`. It makes [`JointKind`], [`JointDef`] and [`Joint`], their
/// conversions, [`JointOfKind`], and the match of every dispatching method.
/// A new kind is its file and one line here.
macro_rules! joint_kinds {
    ($( $(#[$doc:meta])* $kind:ident($joint:ident, $def:ident), )*) => {
        // Every kind's base sits first (see `Joint::base`).
        $( const _: () = assert!(std::mem::offset_of!($joint, base) == 0); )*

        /// The joint kinds.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        pub enum JointKind { $( $(#[$doc])* $kind, )* }

        /// Everything needed to create a joint of any kind (the API
        /// boundary's one type: `World::create_joint` takes it).
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
        pub enum JointDef { $( $(#[$doc])* $kind($def), )* }

        /// A joint in solver form: one variant per kind.
        #[derive(Clone, Debug, PartialEq)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        pub enum Joint { $( $(#[$doc])* $kind($joint), )* }

        $(
            impl From<$def> for JointDef {
                fn from(def: $def) -> Self {
                    JointDef::$kind(def)
                }
            }
            impl $joint {
                /// The definition it was made from, as it stands (kept
                /// boxed, apart from the rows the solver sweeps).
                #[inline]
                #[must_use]
                pub fn def(&self) -> &$def {
                    &self.def
                }
            }
            impl From<$joint> for Joint {
                fn from(j: $joint) -> Self {
                    let mut j = Joint::$kind(j);
                    j.keep_def_reads();
                    j
                }
            }
            impl JointOfKind for $joint {
                const KIND: JointKind = JointKind::$kind;
                type Def = $def;
                fn from_joint(joint: &Joint) -> Option<&Self> {
                    match joint {
                        Joint::$kind(j) => Some(j),
                        #[allow(unreachable_patterns)]
                        _ => None,
                    }
                }
                fn from_joint_mut(joint: &mut Joint) -> Option<&mut Self> {
                    match joint {
                        Joint::$kind(j) => Some(j),
                        #[allow(unreachable_patterns)]
                        _ => None,
                    }
                }
                fn def(&self) -> &$def {
                    &self.def
                }
            }
        )*

        impl JointKind {
            /// Every kind, in the order of the kind list.
            pub const ALL: &'static [JointKind] = &[$(JointKind::$kind,)*];
        }

        impl JointDef {
            /// The kind of joint this defines.
            #[must_use]
            pub fn kind(&self) -> JointKind {
                match self { $( JointDef::$kind(_) => JointKind::$kind, )* }
            }

            /// The shared part of the definition.
            #[must_use]
            pub fn base(&self) -> &JointDefBase {
                match self { $( JointDef::$kind(d) => KindDef::base(d), )* }
            }

            /// The shared part of the definition, mutable.
            pub fn base_mut(&mut self) -> &mut JointDefBase {
                match self { $( JointDef::$kind(d) => KindDef::base_mut(d), )* }
            }

            /// Checks the definition's own values (not the handles).
            pub fn validate(&self) -> Result<(), JointError> {
                match self { $( JointDef::$kind(d) => KindDef::validate(d), )* }
            }

            /// The limits, when the kind has them.
            pub fn limits_mut(&mut self) -> Option<LimitsMut<'_>> {
                match self { $( JointDef::$kind(d) => d.limits_mut(), )* }
            }

            /// The motor, when the kind has one.
            pub fn motor_mut(&mut self) -> Option<MotorMut<'_>> {
                match self { $( JointDef::$kind(d) => d.motor_mut(), )* }
            }

            /// The spring, when the kind has one.
            pub fn spring_mut(&mut self) -> Option<SpringMut<'_>> {
                match self { $( JointDef::$kind(d) => d.spring_mut(), )* }
            }
        }

        impl Joint {
            /// A joint from a definition (validate it first).
            #[must_use]
            pub fn new(def: JointDef) -> Self {
                let mut j = match def { $( JointDef::$kind(d) => Joint::$kind($joint::new(d)), )* };
                j.keep_def_reads();
                j
            }

            /// Its kind.
            #[must_use]
            pub fn kind(&self) -> JointKind {
                match self { $( Joint::$kind(_) => JointKind::$kind, )* }
            }

            /// Its definition as it stands (limits, motor and spring as last set).
            #[must_use]
            pub fn def(&self) -> JointDef {
                match self { $( Joint::$kind(j) => JointDef::$kind((*j.def).clone()), )* }
            }

            /// The shared part of its definition.
            #[must_use]
            pub fn def_base(&self) -> &JointDefBase {
                match self { $( Joint::$kind(j) => &j.def.base, )* }
            }

            /// Asks the cache for every line of its boxed definition, a
            /// few joints before the prepare reads it: a hint only, it
            /// reads and changes nothing. (A revolute definition spans
            /// two lines; asking for the first alone left the prepare
            /// waiting on the second's switches.)
            #[inline]
            pub fn prefetch_def(&self) {
                match self { $( Joint::$kind(j) => janus2d_core::hint::prefetch_all(&*j.def), )* }
            }

            fn def_base_mut(&mut self) -> &mut JointDefBase {
                match self { $( Joint::$kind(j) => &mut j.def.base, )* }
            }

            /// Replaces its definition by `def` of the same kind and the
            /// same bodies (validated), keeping its impulses; an error
            /// leaves it unchanged.
            pub fn set_def(&mut self, def: JointDef) -> Result<(), JointError> {
                def.validate()?;
                if def.kind() != self.kind() {
                    return Err(JointError::WrongKind);
                }
                let (a, b) = (def.base().body_a, def.base().body_b);
                if (a, b) != self.bodies() || def.base().collide_connected != self.collide_connected() {
                    return Err(JointError::FixedField);
                }
                match (&mut *self, def) {
                    $( (Joint::$kind(j), JointDef::$kind(d)) => *j.def = d, )*
                    #[allow(unreachable_patterns)]
                    _ => return Err(JointError::WrongKind),
                }
                self.keep_def_reads();
                Ok(())
            }

            /// The common solver data. Every kind is `repr(C)` with its
            /// base first, so the base sits at one offset in every variant
            /// and this match compiles to one address, not a jump table
            /// (the measurement is in docs/performance.md).
            #[inline(always)]
            #[must_use]
            pub fn base(&self) -> &JointBase {
                match self { $( Joint::$kind(j) => KindRows::base(j), )* }
            }

            #[inline(always)]
            pub(crate) fn base_mut(&mut self) -> &mut JointBase {
                match self { $( Joint::$kind(j) => KindRows::base_mut(j), )* }
            }

            /// A motor of nonzero strength drives the joint's bodies (the
            /// light clusters leave such bodies out).
            #[must_use]
            pub fn is_driven(&self) -> bool {
                self.base().driven
            }

            fn drives(&self) -> bool {
                match self { $( Joint::$kind(j) => KindRows::is_driven(j), )* }
            }

            /// Rows this joint adds to the solver when enabled.
            #[must_use]
            pub fn row_count(&self) -> usize {
                match self { $( Joint::$kind(j) => KindRows::row_count(j), )* }
            }

            /// Force the joint applied to body b over the last solved step, N.
            #[must_use]
            pub fn constraint_force(&self) -> Vec2 {
                match self { $( Joint::$kind(j) => KindRows::constraint_force(j), )* }
            }

            /// Torque the joint applied to body b over the last solved step, N·m.
            #[must_use]
            pub fn constraint_torque(&self) -> Real {
                match self { $( Joint::$kind(j) => KindRows::constraint_torque(j), )* }
            }

            /// [`constraint_force`](Self::constraint_force) and
            /// [`constraint_torque`](Self::constraint_torque) read together.
            #[must_use]
            pub fn read_back(&self) -> (Vec2, Real) {
                match self {
                    $( Joint::$kind(j) => (KindRows::constraint_force(j), KindRows::constraint_torque(j)), )*
                }
            }

            /// Carries the joint through a portal when both ends move to
            /// the other side (`rotation = Q`, `scale = 1/η`): its kept
            /// impulses turned and scaled, its lengths scaled by `η` (see
            /// [`RevoluteJoint::carry_through_portal`]).
            pub fn carry_through_portal(&mut self, rotation: Rot, scale: Real) {
                match self { $( Joint::$kind(j) => KindRows::carry_through_portal(j, rotation, scale), )* }
                // Its lengths changed (a rope's bounds decide its rows).
                self.keep_def_reads();
            }

            #[inline(always)]
            pub(crate) fn tree_rows(&self) -> Option<TreeRows<'_>> {
                match self { $( Joint::$kind(j) => KindRows::tree_rows(j), )* }
            }

            #[cfg(test)]
            pub(crate) fn tree_point_mut(&mut self) -> Option<&mut PointPart> {
                match self { $( Joint::$kind(j) => KindRows::tree_point_mut(j), )* }
            }

            #[inline(always)]
            pub(crate) fn set_tree_impulses(&mut self, impulses: [Real; 3]) {
                match self { $( Joint::$kind(j) => KindRows::set_tree_impulses(j, impulses), )* }
            }

            #[inline(always)]
            pub(crate) fn tree_general_rows(&self, sa: &BodyState, sb: &BodyState) -> GeneralRows {
                match self { $( Joint::$kind(j) => KindRows::tree_general_rows(j, sa, sb), )* }
            }

            #[inline(always)]
            pub(crate) fn has_iterative_rows(&self) -> bool {
                match self { $( Joint::$kind(j) => KindRows::has_iterative_rows(j), )* }
            }

            #[inline(always)]
            pub(crate) fn warm_start_side(&self, st: &mut BodyState, side_b: bool) {
                match self { $( Joint::$kind(j) => crate::kind_rows::warm_start_side(j, st, side_b), )* }
            }

            #[inline(always)]
            pub(crate) fn solve_pair<P: PairStates>(
                &mut self,
                ctx: &StepContext,
                pair: &mut P,
                use_bias: bool,
            ) {
                match self { $( Joint::$kind(j) => crate::kind_rows::solve_pair(j, ctx, pair, use_bias), )* }
            }
        }

        impl Constraint for Joint {
            fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
                match self { $( Joint::$kind(j) => Constraint::prepare(j, ctx, bodies), )* }
            }

            fn warm_start(&mut self, _ctx: &StepContext, states: &mut [BodyState]) {
                match self { $( Joint::$kind(j) => crate::kind_rows::warm_start_states(j, states), )* }
            }

            fn solve(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
                let (a, b) = (self.base().state_a, self.base().state_b);
                let mut pair = PairOf::new(states, a, b, BOTH);
                self.solve_pair(ctx, &mut pair, use_bias);
            }

            fn rows(&self, ctx: &StepContext, bodies: &BodySet) -> ConstraintRows {
                match self { $( Joint::$kind(j) => Constraint::rows(j, ctx, bodies), )* }
            }

            fn is_enabled(&self) -> bool {
                self.base().enabled
            }
        }
    };
}

joint_kinds! {
    /// A pin: two anchors coincide; optional limit, motor and spring.
    Revolute(RevoluteJoint, RevoluteJointDef),
    /// A slide: b moves along an axis fixed in a, the relative angle
    /// locked; optional limits, linear motor and spring.
    Prismatic(PrismaticJoint, PrismaticJointDef),
    /// A weld: two anchors coincide and the relative angle is held,
    /// rigidly or through springs.
    Weld(WeldJoint, WeldJointDef),
    /// A distance: two anchors at a length (rigid or spring), between a
    /// minimum and a maximum (a rope), with a motor along the line.
    Distance(DistanceJoint, DistanceJointDef),
    /// A wheel: b's centre moves along a's suspension axis on a spring and
    /// turns freely; optional limits and a rotational motor.
    Wheel(WheelJoint, WheelJointDef),
    /// A motor: drives b's pose relative to a toward a target offset and
    /// angle, with a largest force and torque.
    Motor(MotorJoint, MotorJointDef),
    /// A mouse (target) joint: pulls a point of body b toward a world
    /// target with a spring of bounded force.
    Mouse(MouseJoint, MouseJointDef),
    /// A filter: no rows; its two bodies do not collide.
    Filter(FilterJoint, FilterJointDef),
}

impl JointDef {
    /// The two bodies `(a, b)`.
    #[must_use]
    pub fn bodies(&self) -> (BodyHandle, BodyHandle) {
        let base = self.base();
        (base.body_a, base.body_b)
    }

    /// Whether the two bodies collide with each other.
    #[must_use]
    pub fn collide_connected(&self) -> bool {
        self.base().collide_connected
    }
}

impl Joint {
    /// Whether the joint's Gauss–Seidel rows may run in lanes: a revolute
    /// joint with angle rows, as its last prepare switched them
    /// ([`crate::revolute_lanes`]).
    #[inline]
    pub(crate) fn lane_candidate(&self) -> bool {
        matches!(self, Joint::Revolute(r) if r.has_prepared_angle_rows())
    }

    /// The joint of kind `K`, if it is one (`joint.of::<RevoluteJoint>()`).
    #[must_use]
    pub fn of<K: JointOfKind>(&self) -> Option<&K> {
        K::from_joint(self)
    }

    /// The revolute joint, if it is one.
    #[must_use]
    pub fn as_revolute(&self) -> Option<&RevoluteJoint> {
        self.of()
    }

    /// The weld joint, if it is one.
    #[must_use]
    pub fn as_weld(&self) -> Option<&WeldJoint> {
        self.of()
    }

    /// The two bodies `(a, b)`.
    #[must_use]
    pub fn bodies(&self) -> (BodyHandle, BodyHandle) {
        let base = self.def_base();
        (base.body_a, base.body_b)
    }

    /// Whether its bodies collide with each other.
    #[must_use]
    pub fn collide_connected(&self) -> bool {
        self.def_base().collide_connected
    }

    /// The local anchors on a and b (in each body's frame), m.
    #[must_use]
    pub fn local_anchors(&self) -> (Vec2, Vec2) {
        let base = self.def_base();
        (base.local_frame_a.anchor, base.local_frame_b.anchor)
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
    #[inline]
    #[must_use]
    pub fn in_tree(&self) -> bool {
        self.base().in_tree
    }

    /// Copies what the step's end and the contact building read of the
    /// definition into the base ([`JointBase::rows`],
    /// [`JointBase::watched`], [`JointBase::driven`]): the definition
    /// is boxed apart, and one more line per joint in those passes was a
    /// tenth of a joint-only step's end. Run whenever the definition
    /// changes (made, [`Joint::set_def`], carried through a portal), not at
    /// each prepare.
    fn keep_def_reads(&mut self) {
        let rows = u8::try_from(self.row_count()).unwrap_or(u8::MAX);
        let driven = self.drives();
        let base = self.def_base();
        let watched =
            base.force_threshold < Real::INFINITY || base.torque_threshold < Real::INFINITY;
        let b = self.base_mut();
        b.rows = rows;
        b.watched = watched;
        b.driven = driven;
    }

    /// Rows it added to the solver at the last prepare when enabled (the
    /// definition's [`Joint::row_count`] as it was then; a step's row
    /// count reads this, not the definition).
    #[inline]
    #[must_use]
    pub fn prepared_row_count(&self) -> usize {
        usize::from(self.base().rows)
    }

    /// Rows of this joint the tree solve takes when it is in a tree.
    #[must_use]
    pub fn tree_row_count(&self) -> usize {
        self.tree_rows().map_or(0, |r| r.count())
    }

    /// The world anchors on a and b.
    #[must_use]
    pub fn world_anchors(&self, bodies: &BodySet) -> (Vec2, Vec2) {
        self.def_base().world_anchors(bodies)
    }

    /// Distance between the two world anchors, m.
    #[must_use]
    pub fn gap(&self, bodies: &BodySet) -> Real {
        let (pa, pb) = self.world_anchors(bodies);
        (pb - pa).length()
    }

    /// Moves the end on body `from` to body `to` with the local anchor
    /// `anchor` in `to`'s frame (the frame's angle is kept: a clone is
    /// its original turned as a whole); false when `from` is not one of
    /// its ends.
    pub fn repoint(&mut self, from: BodyHandle, to: BodyHandle, anchor: Vec2) -> bool {
        let base = self.def_base_mut();
        let Some(frame) = base.frame_on_mut(from) else {
            return false;
        };
        frame.anchor = anchor;
        if base.body_a == from {
            base.body_a = to;
        } else {
            base.body_b = to;
        }
        true
    }

    /// Crosses the force and torque thresholds: true when the last
    /// solved step's force or torque is above its threshold and the step
    /// before was not (one event per crossing; falling back below re-arms
    /// it).
    pub fn check_thresholds(&mut self) -> bool {
        let (force, torque) = self.read_back();
        self.check_thresholds_of(force, torque)
    }

    /// [`check_thresholds`](Self::check_thresholds) for a read-back already
    /// taken (`force`, N; `torque`, N·m).
    #[inline]
    pub fn check_thresholds_of(&mut self, force: Vec2, torque: Real) -> bool {
        if !self.base().watched {
            return false;
        }
        let base = self.def_base();
        let (force_threshold, torque_threshold) = (base.force_threshold, base.torque_threshold);
        let over = self.is_enabled()
            && (force.length() > force_threshold || torque.abs() > torque_threshold);
        let b = self.base_mut();
        let crossed = over && !b.over_threshold;
        b.over_threshold = over;
        crossed
    }
}
