//! # janus2d-constraints
//!
//! Constraint types built on [`janus2d_core::constraint::Constraint`]:
//!
//! | type                          | rows | bodies | built from              |
//! |-------------------------------|------|--------|-------------------------|
//! | [`revolute::RevoluteJoint`]   | 2–6  | 2      | point + angle parts     |
//! | [`portal::PortalConstraint`]  | 3    | 4      | portal part + portal map |
//! | [`contact::ContactConstraint`]| 2–4  | 2      | contact rows (normal, friction) |
//!
//! The point rows of joints that form a tree are solved exactly, the
//! whole tree at once ([`joint_tree`]); the joints' Gauss–Seidel rows are
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
pub mod joint_colour;
pub mod joint_tree;
pub mod lane;
pub mod parts;
pub mod portal;
pub mod portal_map;
pub mod revolute;

pub use contact::{ContactConstraint, ContactPointInput};
pub use contact_solver::{ContactBatch, ContactSolver, ObjectMass, PointImpulse};
pub use joint_colour::JointColours;
pub use joint_tree::{JointForest, RevoluteBatch};
pub use portal::{PortalBatch, PortalConstraint, PortalConstraintDef};
pub use portal_map::{Portal, PortalError, PortalMap, PortalPair};
pub use revolute::{RevoluteJoint, RevoluteJointDef};

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
        }
    }
}

impl std::error::Error for JointError {}
