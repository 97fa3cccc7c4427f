//! Typed errors of the world API. Every call that returns one leaves the
//! world exactly as it was.

use janus2d_constraints::JointError;
use janus2d_constraints::PortalError;
use janus2d_core::body::BodyError;
use janus2d_core::geometry::GeometryError;

/// Anything the world API can reject.
#[derive(Clone, Debug, PartialEq)]
pub enum WorldError {
    /// Invalid body input (non-finite values, non-positive mass or inertia, …).
    Body(BodyError),
    /// Invalid joint input (same body twice, non-finite values, bad limits).
    Joint(JointError),
    /// Invalid shape input (degenerate polygon, non-positive radius, …).
    Geometry(GeometryError),
    /// A body handle that is stale (destroyed) or was never issued by this world.
    StaleBody,
    /// A joint handle that is stale or foreign.
    StaleJoint,
    /// A shape handle that is stale or foreign.
    StaleShape,
    /// A portal pair handle that is stale or foreign.
    StalePortal,
    /// Invalid portal input (η ≤ 0, zero direction, non-positive half-width).
    Portal(PortalError),
    /// A time step that is not finite or not positive.
    InvalidTimeStep,
    /// A non-finite value in a world-level input (names it).
    NonFinite(&'static str),
    /// A value outside its allowed range (names it).
    OutOfRange(&'static str),
    /// The operation needs a dynamic body.
    NotDynamic,
}

impl std::fmt::Display for WorldError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WorldError::Body(e) => write!(f, "body: {e}"),
            WorldError::Joint(e) => write!(f, "joint: {e}"),
            WorldError::Geometry(e) => write!(f, "shape: {e}"),
            WorldError::StaleBody => write!(f, "stale or foreign body handle"),
            WorldError::StaleJoint => write!(f, "stale or foreign joint handle"),
            WorldError::StaleShape => write!(f, "stale or foreign shape handle"),
            WorldError::StalePortal => write!(f, "stale or foreign portal pair handle"),
            WorldError::Portal(e) => write!(f, "portal: {e}"),
            WorldError::InvalidTimeStep => write!(f, "time step must be finite and > 0"),
            WorldError::NonFinite(what) => write!(f, "`{what}` is not finite"),
            WorldError::OutOfRange(what) => write!(f, "`{what}` is out of range"),
            WorldError::NotDynamic => write!(f, "operation needs a dynamic body"),
        }
    }
}

impl std::error::Error for WorldError {}

impl From<BodyError> for WorldError {
    fn from(e: BodyError) -> Self {
        match e {
            BodyError::StaleHandle => WorldError::StaleBody,
            e => WorldError::Body(e),
        }
    }
}

impl From<JointError> for WorldError {
    fn from(e: JointError) -> Self {
        WorldError::Joint(e)
    }
}

impl From<GeometryError> for WorldError {
    fn from(e: GeometryError) -> Self {
        WorldError::Geometry(e)
    }
}
