//! What the solver keeps of every joint, whatever its kind.
//!
//! | field              | set by            | read by                                   |
//! |--------------------|-------------------|-------------------------------------------|
//! | `state_a`, `state_b` | prepare (`load`) | the kind's rows, colouring keys, tree solve |
//! | `masses`           | prepare (`load`)  | the kind's rows, tree solve               |
//! | `enabled`          | the world         | every stage (a disabled joint is skipped) |
//! | `resting`          | prepare (`load`)  | every stage (neither body moves)          |
//! | `in_tree`          | the tree build    | the kind's rows (tree rows skipped), colouring |
//! | `inv_h`            | prepare (`load`)  | force and torque read-back                |

use janus2d_core::body::{BodyHandle, BodySet, BodyState, SolverBody};
use janus2d_core::constraint::StepContext;
use janus2d_core::math::{Real, Vec2, wrap_angle};

use crate::parts::PairMass;

/// What the solver keeps of every joint, whatever its kind: the state
/// indices and masses loaded at prepare and the switches the colouring and
/// the tree solve read.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct JointBase {
    /// False when the joint is disabled (skipped by the solver).
    pub(crate) enabled: bool,
    /// Body a's state index (0: the static identity state).
    pub(crate) state_a: u32,
    /// Body b's state index.
    pub(crate) state_b: u32,
    /// The bodies' inverse masses, loaded at prepare (zero for a body on
    /// the static identity state).
    pub(crate) masses: PairMass,
    /// True while the joint's equality rows belong to the direct solve of a
    /// joint tree (set every step by [`JointForest`](crate::joint_tree::JointForest)).
    pub(crate) in_tree: bool,
    /// Neither body moves this step (both static or asleep): the joint is
    /// not solved and keeps its last impulses, so its read-back holds.
    pub(crate) resting: bool,
    /// `1 / h` of the last step the joint was solved in, 1/s (turns the
    /// per-substep impulses into forces).
    pub(crate) inv_h: Real,
}

impl Default for JointBase {
    fn default() -> Self {
        JointBase {
            enabled: true,
            state_a: 0,
            state_b: 0,
            masses: PairMass::ZERO,
            in_tree: false,
            resting: false,
            inv_h: 0.0,
        }
    }
}

impl JointBase {
    /// Loads the state indices and masses of the two bodies for a step;
    /// returns the bodies, or `None` when neither moves (the joint rests
    /// this step and keeps its impulses).
    #[inline]
    pub(crate) fn load<'b>(
        &mut self,
        ctx: &StepContext,
        bodies: &'b BodySet,
        body_a: BodyHandle,
        body_b: BodyHandle,
    ) -> Option<(SolverBody<'b>, SolverBody<'b>)> {
        let a = bodies.solver_body(body_a);
        let b = bodies.solver_body(body_b);
        self.state_a = a.state_index;
        self.state_b = b.state_index;
        self.resting = a.state_index == 0 && b.state_index == 0;
        if self.resting {
            return None;
        }
        self.inv_h = ctx.inv_h;
        self.masses = PairMass {
            a: a.inv_masses(),
            b: b.inv_masses(),
        };
        Some((a, b))
    }
}

/// A body that the solve moves: a state of its own (not the static
/// identity 0) whose body is dynamic ([`BodyState::MOVES`]); false for an
/// index past the states.
#[inline]
pub(crate) fn is_moving(states: &[BodyState], s: u32) -> bool {
    s != 0 && states.get(s as usize).is_some_and(BodyState::moves)
}

/// The world points of two local anchors: `anchor_a` on `body_a`, `anchor_b`
/// on `body_b` (each in its body's frame, from the body's origin), m. Every
/// kind's `world_anchors` and gap read.
#[must_use]
pub fn world_anchors(
    bodies: &BodySet,
    (body_a, anchor_a): (BodyHandle, Vec2),
    (body_b, anchor_b): (BodyHandle, Vec2),
) -> (Vec2, Vec2) {
    let a = bodies.solver_body(body_a).sim;
    let b = bodies.solver_body(body_b).sim;
    (a.transform.apply(anchor_a), b.transform.apply(anchor_b))
}

/// The relative angle `θ_b − θ_a − reference`, rad, wrapped to `[−π, π]`.
#[must_use]
pub fn relative_angle(
    bodies: &BodySet,
    body_a: BodyHandle,
    body_b: BodyHandle,
    reference: Real,
) -> Real {
    let a = bodies.solver_body(body_a).sim;
    let b = bodies.solver_body(body_b).sim;
    wrap_angle(a.transform.q.relative_angle(b.transform.q) - reference)
}
