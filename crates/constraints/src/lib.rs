//! # janus2d-constraints
//!
//! Constraint types built on [`janus2d_core::constraint::Constraint`]:
//!
//! | type                          | rows | bodies | built from              |
//! |-------------------------------|------|--------|-------------------------|
//! | [`joint::Joint`]              | per kind | 2  | one file per kind ([`joint`]) |
//! | [`revolute::RevoluteJoint`]   | 2–6  | 2      | point + angle parts     |
//! | [`weld::WeldJoint`]           | 3    | 2      | point + angle parts     |
//! | [`motor::MotorJoint`]         | 3    | 2      | point + angle parts, force- and torque-bounded |
//! | [`filter::FilterJoint`]       | 0    | 2      | nothing (only stops the pair colliding) |
//! | [`prismatic::PrismaticJoint`] | 2–6  | 2      | axis rows + angle row   |
//! | [`wheel::WheelJoint`]         | 1–5  | 2      | axis rows + angle motor |
//! | [`distance::DistanceJoint`]   | 0–4  | 2      | axis rows along the anchors' line |
//! | [`mouse::MouseJoint`]         | 2–3  | 2 (moves b only) | soft point toward a world target + angular damping |
//! | [`portal::PortalConstraint`]  | 3    | 4      | portal part + portal map |
//! | [`contact::ContactConstraint`]| 2–4  | 2      | contact rows (normal, friction) |
//!
//! The equality rows of joints that form a tree (a revolute joint's
//! point, a rigid weld's point and angle) are solved exactly, the whole
//! tree at once ([`joint_tree`]); the joints' Gauss–Seidel rows are
//! solved colour by colour on the step's team ([`joint_colour`]); so are the normal rows of the
//! contacts of a light cluster, bodies under (or between) bodies ten times
//! heavier or more ([`contact_group`]); the rest is Gauss–Seidel.
//!
//! Every type follows the same stages (prepare, warm start, solve with or
//! without bias) and reports its rows through `Constraint::rows`. The
//! contact rows are written once ([`contact_row`]), generic over the lane
//! type ([`lane::Lane`]): one contact at a time in the scalar overflow,
//! [`lane::LANES`] at a time in the colours' SIMD chunks; every soft row
//! takes the same soft update ([`parts::soft_impulse`]).

pub mod contact;
pub mod contact_group;
pub mod contact_row;
pub mod contact_solver;
pub mod distance;
pub mod filter;
pub mod graph_solver;
pub mod joint;
pub mod joint_base;
pub mod joint_colour;
pub mod joint_def;
pub(crate) mod joint_rows;
pub mod joint_solver;
pub mod joint_tree;
pub(crate) mod kind_rows;
pub mod lane;
pub mod motor;
pub mod mouse;
pub mod parts;
pub mod portal;
pub mod portal_map;
pub mod prismatic;
pub mod revolute;
pub(crate) mod revolute_lanes;
pub mod weld;
pub mod wheel;

/// What several modules' tests share.
#[cfg(test)]
pub(crate) mod test_support {
    use janus2d_core::body::BodySet;
    use janus2d_core::constraint::{ConstraintBatch, StepContext};
    use janus2d_core::parallel::Team;

    /// Prepares `batch` and runs three substeps' velocity stages on
    /// `set`'s states, as the solver does (warm start, solve, late pass,
    /// relax; the sweeps alternating direction).
    pub(crate) fn three_substeps(
        batch: &mut dyn ConstraintBatch,
        ctx: &StepContext,
        set: &mut BodySet,
        team: &Team,
    ) {
        batch.prepare_on(ctx, set, team);
        for flip in [false, true, false] {
            let states = &mut set.states;
            batch.warm_start_on(ctx, states, team);
            batch.solve_on(ctx, states, true, flip, team);
            batch.solve_late_on(ctx, states, true, team);
            batch.solve_on(ctx, states, false, !flip, team);
        }
    }
}

pub use contact::{ContactConstraint, ContactPointInput};
pub use contact_solver::{ContactBatch, ContactSolver, ObjectMass, PointImpulse};
pub use distance::{DistanceJoint, DistanceJointDef};
pub use filter::{FilterJoint, FilterJointDef};
pub use graph_solver::GraphBatch;
pub use joint::{Joint, JointDef, JointKind, JointOfKind};
pub use joint_base::JointBase;
pub use joint_colour::JointColours;
pub use joint_def::{JointDefBase, JointFrame, KindDef, LimitsMut, MotorMut, SpringMut};
pub use joint_solver::JointBatch;
pub use joint_tree::{JointForest, TreePolicy};
pub use motor::{MotorJoint, MotorJointDef};
pub use mouse::{MouseJoint, MouseJointDef};
pub use portal::{PortalBatch, PortalConstraint, PortalConstraintDef};
pub use portal_map::{Portal, PortalError, PortalMap, PortalPair};
pub use prismatic::{PrismaticJoint, PrismaticJointDef};
pub use revolute::{RevoluteJoint, RevoluteJointDef};
pub use weld::{WeldJoint, WeldJointDef};
pub use wheel::{WheelJoint, WheelJointDef};

/// Invalid joint input at the API boundary.
#[derive(Clone, Debug, PartialEq)]
pub enum JointError {
    /// Both ends name the same body.
    SameBody,
    /// A value that must be finite is not.
    NonFinite,
    /// A value that must be ≥ 0 is negative.
    Negative,
    /// The lower limit exceeds the upper limit.
    InvalidLimits,
    /// A body the definition names is not in the body set.
    UnknownBody,
    /// A definition of another kind than the joint's.
    WrongKind,
    /// A change to what is fixed for a joint's life (its bodies,
    /// `collide_connected`).
    FixedField,
    /// A length that must be positive is not (a rope's maximum, a
    /// distance joint's rest length).
    ZeroLength,
    /// A value outside the range the engine accepts (see
    /// [`janus2d_core::limits`]); the world reports it as its own
    /// `OutOfBounds`.
    OutOfBounds {
        /// The field.
        field: &'static str,
        /// Smallest accepted value.
        min: janus2d_core::math::Real,
        /// Largest accepted value.
        max: janus2d_core::math::Real,
    },
}

/// Checks a local anchor against
/// [`MAX_EXTENT`](janus2d_core::limits::MAX_EXTENT), m.
pub fn check_anchor(
    anchor: janus2d_core::math::Vec2,
    field: &'static str,
) -> Result<(), JointError> {
    let max = janus2d_core::limits::MAX_EXTENT;
    if anchor.x.abs() > max || anchor.y.abs() > max {
        return Err(JointError::OutOfBounds {
            field,
            min: -max,
            max,
        });
    }
    Ok(())
}

/// Checks a motor speed against
/// [`MAX_ANGULAR_SPEED`](janus2d_core::limits::MAX_ANGULAR_SPEED), rad/s.
pub fn check_motor_speed(speed: janus2d_core::math::Real) -> Result<(), JointError> {
    let max = janus2d_core::limits::MAX_ANGULAR_SPEED;
    if speed.abs() > max {
        return Err(JointError::OutOfBounds {
            field: "motor_speed",
            min: -max,
            max,
        });
    }
    Ok(())
}

/// Checks a spring against
/// [`MAX_SPRING_HERTZ`](janus2d_core::limits::MAX_SPRING_HERTZ) and
/// [`MAX_DAMPING_RATIO`](janus2d_core::limits::MAX_DAMPING_RATIO).
pub fn check_spring(
    hertz: janus2d_core::math::Real,
    damping_ratio: janus2d_core::math::Real,
) -> Result<(), JointError> {
    let max_hertz = janus2d_core::limits::MAX_SPRING_HERTZ;
    if hertz > max_hertz {
        return Err(JointError::OutOfBounds {
            field: "hertz",
            min: 0.0,
            max: max_hertz,
        });
    }
    let max = janus2d_core::limits::MAX_DAMPING_RATIO;
    if damping_ratio > max {
        return Err(JointError::OutOfBounds {
            field: "damping_ratio",
            min: 0.0,
            max,
        });
    }
    Ok(())
}

impl std::fmt::Display for JointError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            JointError::SameBody => write!(f, "a joint needs two different bodies"),
            JointError::NonFinite => write!(f, "joint definition has a non-finite value"),
            JointError::Negative => write!(
                f,
                "joint definition has a negative torque, hertz or damping"
            ),
            JointError::InvalidLimits => write!(f, "joint lower limit exceeds upper limit"),
            JointError::UnknownBody => write!(f, "joint definition names a body not in the set"),
            JointError::WrongKind => write!(f, "joint definition of another kind than the joint"),
            JointError::FixedField => write!(
                f,
                "a joint's bodies and collide_connected are fixed for its life"
            ),
            JointError::ZeroLength => write!(f, "joint length must be positive"),
            JointError::OutOfBounds { field, min, max } => {
                write!(f, "joint {field} outside [{min}, {max}]")
            }
        }
    }
}

impl std::error::Error for JointError {}
