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
//! | `over_threshold`   | the joint events  | the joint events (one per crossing)       |
//! | `rows`, `watched`, `driven` | prepare, a new or replaced definition | the step's end (row count, joint events), the light clusters (driven bodies) |

use janus2d_core::body::{BodyHandle, BodySet, BodyState, SolverBody};
use janus2d_core::constraint::{BodyJacobian, Row, StepContext};
use janus2d_core::math::{Real, Vec2, cross, wrap_angle};
use janus2d_core::softness::Softness;
use smallvec::smallvec;

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
    /// The last solved step's force or torque was above its threshold
    /// (the joint events report the crossing once).
    pub(crate) over_threshold: bool,
    /// Rows the definition adds when the joint is enabled (kept so the
    /// step's end reads no definition).
    pub(crate) rows: u8,
    /// The definition has a finite force or torque threshold.
    pub(crate) watched: bool,
    /// A motor of nonzero strength drives the bodies.
    pub(crate) driven: bool,
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
            over_threshold: false,
            rows: 0,
            watched: false,
            driven: false,
        }
    }
}

impl JointBase {
    /// `1 / h` of the last step the joint was solved in, 1/s (0 before
    /// its first step).
    #[must_use]
    pub fn inv_h(&self) -> Real {
        self.inv_h
    }

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

/// A two-body joint's geometry at the bodies' current poses, from which
/// each kind's `rows()` report builds its rows: the arms from the centres
/// of mass, the point error `C = (x_b + r_b) − (x_a + r_a)` and the masses.
pub(crate) struct RowsAt {
    body_a: BodyHandle,
    body_b: BodyHandle,
    /// Arm of the anchor on a, m.
    pub(crate) r_a: Vec2,
    /// Arm of the anchor on b, m.
    pub(crate) r_b: Vec2,
    /// The point error, m.
    pub(crate) c: Vec2,
    /// The two bodies' inverse masses as the solve loads them.
    pub(crate) m: PairMass,
}

impl RowsAt {
    /// The geometry of a joint's two frames' anchors (each in its body's
    /// frame, from its origin).
    pub(crate) fn new(bodies: &BodySet, def: &crate::joint_def::JointDefBase) -> RowsAt {
        Self::at_points(
            bodies,
            (def.body_a, def.local_frame_a.anchor),
            (def.body_b, def.local_frame_b.anchor),
        )
    }

    /// The geometry of any two local points (`anchor_a` on `body_a`,
    /// `anchor_b` on `body_b`, each in its body's frame, from its origin):
    /// for a kind whose point rows hold other points than the frames'
    /// origins (the motor joint's target point).
    pub(crate) fn at_points(
        bodies: &BodySet,
        (body_a, anchor_a): (BodyHandle, Vec2),
        (body_b, anchor_b): (BodyHandle, Vec2),
    ) -> RowsAt {
        let a = bodies.solver_body(body_a);
        let b = bodies.solver_body(body_b);
        let r_a = a.sim.transform.q.rotate(anchor_a - a.sim.local_center);
        let r_b = b.sim.transform.q.rotate(anchor_b - b.sim.local_center);
        RowsAt {
            body_a,
            body_b,
            r_a,
            r_b,
            c: (b.sim.center + r_b) - (a.sim.center + r_a),
            m: PairMass {
                a: a.inv_masses(),
                b: b.inv_masses(),
            },
        }
    }

    /// A row with Jacobian `[linear[0], angular[0] │ linear[1], angular[1]]`.
    fn row(&self, linear: [Vec2; 2], angular: [Real; 2], c: Real, softness: Softness) -> Row {
        let m = &self.m;
        let entry = |body, linear, angular, inv_mass, inv_inertia| BodyJacobian {
            body,
            linear,
            angular,
            inv_mass,
            inv_inertia,
        };
        Row {
            jacobian: smallvec![
                entry(
                    self.body_a,
                    linear[0],
                    angular[0],
                    m.a.inv_mass,
                    m.a.inv_inertia
                ),
                entry(
                    self.body_b,
                    linear[1],
                    angular[1],
                    m.b.inv_mass,
                    m.b.inv_inertia
                ),
            ],
            c,
            softness,
            lower: Real::NEG_INFINITY,
            upper: Real::INFINITY,
            impulse: 0.0,
        }
    }

    /// The point row along `axis`: `J = [−axis, −r_a × axis │ axis, r_b × axis]`.
    pub(crate) fn point_row(&self, axis: Vec2, c: Real, softness: Softness, impulse: Real) -> Row {
        let angular = [-cross(self.r_a, axis), cross(self.r_b, axis)];
        Row {
            impulse,
            ..self.row([-axis, axis], angular, c, softness)
        }
    }

    /// A row along a direction `n` (an [`AxisRow`](crate::parts::AxisRow)):
    /// `J = [−n, −s_a │ n, s_b]` with impulse bounds.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn axis_row(
        &self,
        n: Vec2,
        (s_a, s_b): (Real, Real),
        c: Real,
        softness: Softness,
        (lower, upper): (Real, Real),
        impulse: Real,
    ) -> Row {
        Row {
            lower,
            upper,
            impulse,
            ..self.row([-n, n], [-s_a, s_b], c, softness)
        }
    }

    /// An angle row `J = [0, −sign │ 0, sign]` with impulse bounds.
    pub(crate) fn angle_row(
        &self,
        sign: Real,
        c: Real,
        softness: Softness,
        (lower, upper): (Real, Real),
        impulse: Real,
    ) -> Row {
        Row {
            lower,
            upper,
            impulse,
            ..self.row([Vec2::ZERO; 2], [-sign, sign], c, softness)
        }
    }
}
