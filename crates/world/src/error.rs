//! Typed errors of the world API. Every call that returns one leaves the
//! world exactly as it was.

use janus2d_constraints::JointError;
use janus2d_constraints::PortalError;
use janus2d_core::body::BodyError;
use janus2d_core::geometry::GeometryError;
use janus2d_core::math::Real;

/// Anything the world API can reject.
#[derive(Clone, Debug, PartialEq)]
pub enum WorldError {
    /// Invalid body input (non-finite values, non-positive mass or inertia, …).
    Body(BodyError),
    /// Invalid joint input (same body twice, non-finite values, bad limits).
    Joint(JointError),
    /// Invalid shape input (degenerate polygon, non-positive radius, …).
    Geometry(GeometryError),
    /// A body handle that is stale (the body was destroyed).
    StaleBody,
    /// A joint handle that is stale.
    StaleJoint,
    /// A live joint handle used where another kind of joint is needed (a
    /// typed accessor or a setter that the joint's kind does not have).
    WrongJointKind,
    /// A shape handle that is stale.
    StaleShape,
    /// A portal pair handle that is stale.
    StalePortal,
    /// A chain handle that is stale (the chain or its body was destroyed).
    StaleChain,
    /// The shape is a segment of a chain: it goes with its chain
    /// ([`World::destroy_chain`](crate::World::destroy_chain)), not alone.
    ChainSegmentShape,
    /// A handle (of any kind) that another world issued.
    ForeignHandle,
    /// Invalid portal input (η ≤ 0, zero direction, non-positive half-width).
    Portal(PortalError),
    /// A time step that is not finite or not positive.
    InvalidTimeStep,
    /// A non-finite value in a world-level input (names it).
    NonFinite(&'static str),
    /// A value outside its allowed range (names it).
    OutOfRange(&'static str),
    /// A finite value outside its stated range (see
    /// [`janus2d_core::limits`]): names the field and the range (for a
    /// magnitude, `min = -max`).
    OutOfBounds {
        /// The field at fault.
        field: &'static str,
        /// Smallest allowed value.
        min: Real,
        /// Largest allowed value.
        max: Real,
    },
    /// The operation needs a dynamic body.
    NotDynamic,
    /// The operation needs a kinematic or dynamic body (not a static one).
    NotMovable,
    /// The body carries a portal or is crossing one: the operation would
    /// break the portal stage's bookkeeping.
    PortalBody,
    /// The body is disabled ([`World::set_body_enabled`](crate::World::set_body_enabled)):
    /// enable it first.
    DisabledBody,
    /// A scene query input that is non-finite or degenerate: names the
    /// field (`origin`, `translation`, `point`, `aabb`, `transform`,
    /// `shape`) and what is wrong with it.
    BadQuery {
        /// The input at fault.
        field: &'static str,
        /// What is wrong with it.
        problem: QueryProblem,
    },
}

impl std::fmt::Display for WorldError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WorldError::Body(e) => write!(f, "body: {e}"),
            WorldError::Joint(e) => write!(f, "joint: {e}"),
            WorldError::Geometry(e) => write!(f, "shape: {e}"),
            WorldError::StaleBody => write!(f, "stale body handle"),
            WorldError::StaleJoint => write!(f, "stale joint handle"),
            WorldError::WrongJointKind => write!(f, "the joint is of another kind"),
            WorldError::StaleShape => write!(f, "stale shape handle"),
            WorldError::StalePortal => write!(f, "stale portal pair handle"),
            WorldError::StaleChain => write!(f, "stale chain handle"),
            WorldError::ChainSegmentShape => {
                write!(f, "the shape is a chain segment: destroy its chain")
            }
            WorldError::ForeignHandle => write!(f, "handle issued by another world"),
            WorldError::Portal(e) => write!(f, "portal: {e}"),
            WorldError::InvalidTimeStep => write!(f, "time step must be finite and > 0"),
            WorldError::NonFinite(what) => write!(f, "`{what}` is not finite"),
            WorldError::OutOfRange(what) => write!(f, "`{what}` is out of range"),
            WorldError::OutOfBounds { field, min, max } => {
                write!(f, "`{field}` must lie in [{min:e}, {max:e}]")
            }
            WorldError::NotDynamic => write!(f, "operation needs a dynamic body"),
            WorldError::NotMovable => write!(f, "operation needs a kinematic or dynamic body"),
            WorldError::PortalBody => write!(f, "the body carries or is crossing a portal"),
            WorldError::DisabledBody => write!(f, "the body is disabled"),
            WorldError::BadQuery { field, problem } => write!(f, "query `{field}` {problem}"),
        }
    }
}

impl std::error::Error for WorldError {}

impl WorldError {
    /// The error of a handle that does not resolve: `ForeignHandle` for
    /// another world's, `stale` (the kind's own stale error) otherwise.
    pub(crate) fn of_handle(e: janus2d_core::handle::HandleError, stale: WorldError) -> Self {
        match e {
            janus2d_core::handle::HandleError::Foreign => WorldError::ForeignHandle,
            janus2d_core::handle::HandleError::Stale => stale,
        }
    }
}

impl From<BodyError> for WorldError {
    fn from(e: BodyError) -> Self {
        match e {
            BodyError::StaleHandle => WorldError::StaleBody,
            e => WorldError::Body(e),
        }
    }
}

impl From<janus2d_core::solver::SettingsError> for WorldError {
    fn from(e: janus2d_core::solver::SettingsError) -> Self {
        match e {
            janus2d_core::solver::SettingsError::NonFinite(name) => WorldError::NonFinite(name),
            janus2d_core::solver::SettingsError::OutOfRange(name) => WorldError::OutOfRange(name),
        }
    }
}

impl From<JointError> for WorldError {
    fn from(e: JointError) -> Self {
        match e {
            // One out-of-range error for every input, as the other setters.
            JointError::OutOfBounds { field, min, max } => {
                WorldError::OutOfBounds { field, min, max }
            }
            e => WorldError::Joint(e),
        }
    }
}

impl From<GeometryError> for WorldError {
    fn from(e: GeometryError) -> Self {
        WorldError::Geometry(e)
    }
}

/// What is wrong with a query input ([`WorldError::BadQuery`]).
#[derive(Clone, Debug, PartialEq)]
pub enum QueryProblem {
    /// A coordinate is NaN or infinite.
    NonFinite,
    /// A translation of zero length (a ray or cast needs a direction).
    ZeroLength,
    /// A box whose lower corner is above its upper corner.
    Inverted,
    /// The query shape is invalid.
    Shape(GeometryError),
    /// A transform's rotation is not a unit rotation: `c² + s²` is
    /// farther than [`UNIT_ROTATION_TOLERANCE`](janus2d_core::limits::UNIT_ROTATION_TOLERANCE)
    /// from 1 (a rotation within it is normalised).
    NotUnitRotation,
    /// A distance or radius below zero.
    Negative,
}

impl std::fmt::Display for QueryProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            QueryProblem::NonFinite => write!(f, "is not finite"),
            QueryProblem::ZeroLength => write!(f, "has zero length"),
            QueryProblem::Inverted => write!(f, "has its lower corner above its upper corner"),
            QueryProblem::Shape(e) => write!(f, "is an invalid shape: {e}"),
            QueryProblem::NotUnitRotation => write!(f, "has a rotation that is not unit length"),
            QueryProblem::Negative => write!(f, "is negative"),
        }
    }
}
