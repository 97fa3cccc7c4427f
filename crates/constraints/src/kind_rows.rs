//! What a joint kind's solver form supplies to the solver, and the rows
//! the exact tree solve takes from it.
//!
//! | item          | read by                                   |
//! |---------------|-------------------------------------------|
//! | [`KindRows`]  | [`crate::joint::Joint`]'s dispatch (static, no `dyn`); its rows go to [`crate::joint_rows`] |
//! | [`TreeRows`]  | the tree build and solve ([`crate::joint_tree`]) |
//! | [`GeneralRows`] | the tree solve's general path           |
//! | [`solve_pair`], [`warm_start_side`] | the colour stages: one iteration / one body's warm start of any kind, through its rows |
//!
//! A kind's file imports this module, never `joint`; `joint` imports the
//! kinds (its enum has a variant per kind), so the two do not form a
//! circle.

use janus2d_core::body::BodyState;
use janus2d_core::constraint::{Constraint, StepContext};
use janus2d_core::math::{Real, Rot, Vec2};

use crate::joint_base::JointBase;
use crate::joint_rows::{RowSolve, WarmSide};
use crate::parts::{BOTH, PairOf, PairStates, PointPart, load_pair, store_pair};

/// What a joint kind's solver form supplies: its rows' stages, read-backs
/// and what the tree solve may take. Dispatched by [`Joint`]'s match
/// (static, no `dyn`); every method but the stages has a default that
/// fits a kind without tree rows.
pub(crate) trait KindRows: Constraint {
    /// The shared solver data.
    fn base(&self) -> &JointBase;
    /// The shared solver data, mutable.
    fn base_mut(&mut self) -> &mut JointBase;
    /// Rows the kind adds to the solver when enabled.
    fn row_count(&self) -> usize;
    /// A motor of nonzero strength drives the bodies.
    fn is_driven(&self) -> bool {
        false
    }
    /// Force on body b over the last solved step, N.
    fn constraint_force(&self) -> Vec2;
    /// Torque on body b over the last solved step, N·m.
    fn constraint_torque(&self) -> Real;
    /// Carries the joint through a portal when both ends cross (`rotation
    /// = Q`, `scale = 1/η`): linear impulses turn and scale, angular ones
    /// are kept, and the world-space lengths the definition holds
    /// (distances, translations, linear offsets and speeds) scale by `η`
    /// as the anchors do.
    fn carry_through_portal(&mut self, rotation: Rot, scale: Real);
    /// The kind's Gauss–Seidel rows at the current positions (read from
    /// `s.sa`, `s.sb`), handed to `s` in solve order
    /// ([`crate::joint_rows`]); called only when the joint has iterative
    /// rows and is not resting.
    fn solve_rows(&mut self, ctx: &StepContext, use_bias: bool, s: &mut RowSolve);
    /// The kept impulses of the kind's rows, handed to `w` for one body's
    /// share of the warm start ([`crate::joint_rows`]).
    fn warm_rows(&self, w: &mut WarmSide<'_>);
    /// The equality rows the tree solve may take (`None`: none).
    fn tree_rows(&self) -> Option<TreeRows<'_>> {
        None
    }
    /// The `General` tree rows at the states `sa`, `sb` (bodies a and b,
    /// positions as deltas since the step's start); only called for a
    /// kind whose `tree_rows` is `TreeRows::General`.
    fn tree_general_rows(&self, _sa: &BodyState, _sb: &BodyState) -> GeneralRows {
        GeneralRows::default()
    }
    /// Takes back the tree's impulses: `[point x, point y, angle]` for
    /// `Point` rows, the rows' impulses in order for `General` rows.
    fn set_tree_impulses(&mut self, _impulses: [Real; 3]) {}
    /// Rows left for the Gauss–Seidel pass this step.
    fn has_iterative_rows(&self) -> bool {
        !self.base().in_tree && self.row_count() > 0
    }
    /// The point part, for the unit tests of the tree.
    #[cfg(test)]
    fn tree_point_mut(&mut self) -> Option<&mut PointPart> {
        None
    }
}

/// A joint's equality rows as the tree solve takes them.
///
/// - `Point`: the point rows, and for a joint that also holds the relative
///   angle the angle row (`C_θ = θ_b − θ_a − θ_ref`,
///   `J_θ = [0 0 −1 │ 0 0 1]`): the specialised paths of the tree.
/// - `General`: up to three rows of any Jacobian, which the kind builds at
///   the tree's current states ([`KindRows::tree_general_rows`]): the
///   general 3×3 path.
#[derive(Clone, Copy, Debug)]
pub(crate) enum TreeRows<'a> {
    /// Point rows (and an angle row).
    Point {
        /// The point part (arms, centre offset, impulse).
        point: &'a PointPart,
        /// The angle row, for a 3-row joint.
        angle: Option<TreeAngle>,
    },
    /// `count` rows the kind builds at the tree's states.
    General {
        /// Number of rows, 1 to 3.
        count: usize,
    },
}

impl TreeRows<'_> {
    /// Number of rows.
    #[inline(always)]
    pub(crate) fn count(&self) -> usize {
        match self {
            TreeRows::Point { angle, .. } => 2 + usize::from(angle.is_some()),
            TreeRows::General { count } => *count,
        }
    }
}

/// The angle row of a joint's point tree rows.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TreeAngle {
    /// `C_θ` at the start of the step, rad.
    pub(crate) delta_angle: Real,
    /// Accumulated impulse, N·m·s.
    pub(crate) impulse: Real,
}

/// Up to three equality rows of a kind at given states, for the tree's
/// general path: row `i` is `J_i = [j_a[i] │ j_b[i]]` with each entry
/// `(linear x, linear y, angular)` on that body, its error `c[i]` and kept
/// impulse; `linear[i]` caps the row's correction speed (a length row;
/// an angle row is not capped). Rows past `count` are unused.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct GeneralRows {
    /// Number of rows, 1 to 3.
    pub(crate) count: usize,
    /// The rows' entries on body a.
    pub(crate) j_a: [[Real; 3]; 3],
    /// The rows' entries on body b.
    pub(crate) j_b: [[Real; 3]; 3],
    /// The rows' errors (m or rad).
    pub(crate) c: [Real; 3],
    /// Whether each row's correction speed is capped.
    pub(crate) linear: [bool; 3],
    /// The rows' accumulated impulses.
    pub(crate) impulse: [Real; 3],
}

/// Whether the Gauss–Seidel pass has work on the joint this step.
#[inline(always)]
fn iterates<K: KindRows>(kind: &K) -> bool {
    !kind.base().resting && kind.has_iterative_rows()
}

/// One velocity iteration of a joint's rows over a pair of states.
#[inline(always)]
pub(crate) fn solve_pair<K: KindRows, P: PairStates>(
    kind: &mut K,
    ctx: &StepContext,
    pair: &mut P,
    use_bias: bool,
) {
    if !iterates(kind) {
        return;
    }
    let (sa, sb) = pair.load();
    let mut s = RowSolve {
        sa,
        sb,
        m: kind.base().masses,
    };
    kind.solve_rows(ctx, use_bias, &mut s);
    pair.store(&s.sa, &s.sb);
}

/// One body's share of a joint's warm start: every kept impulse, the
/// tree's too (the colour stage warm-starts every active joint body by
/// body; the tree solve takes its rows' impulses from there).
#[inline(always)]
pub(crate) fn warm_start_side<K: KindRows>(kind: &K, st: &mut BodyState, side_b: bool) {
    let mut w = WarmSide::new(st, kind.base().masses, side_b);
    kind.warm_rows(&mut w);
}

/// A joint's warm start on the whole state slice: body a's share, then
/// body b's.
pub(crate) fn warm_start_states<K: KindRows>(kind: &K, states: &mut [BodyState]) {
    if kind.base().resting {
        return;
    }
    let (a, b) = (kind.base().state_a, kind.base().state_b);
    let (mut sa, mut sb) = load_pair(states, a, b);
    warm_start_side(kind, &mut sa, false);
    warm_start_side(kind, &mut sb, true);
    store_pair(states, a, b, &sa, &sb);
}

/// One velocity iteration of a joint's rows on the whole state slice.
pub(crate) fn solve_states<K: KindRows>(
    kind: &mut K,
    ctx: &StepContext,
    states: &mut [BodyState],
    use_bias: bool,
) {
    let (a, b) = (kind.base().state_a, kind.base().state_b);
    let mut pair = PairOf::new(states, a, b, BOTH);
    solve_pair(kind, ctx, &mut pair, use_bias);
}
