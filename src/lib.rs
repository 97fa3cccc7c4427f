//! # janus2d
//!
//! A 2D rigid-body physics engine whose signature is the portal. This facade
//! re-exports the three crates:
//!
//! | crate                 | contents                                                   |
//! |-----------------------|------------------------------------------------------------|
//! | [`base`] (janus2d-core) | bodies, integration, the solver, the constraint trait      |
//! | [`constraints`]       | contact, joint (every kind: [`JointDef`]) and portal constraints |
//! | [`world`]             | the stepping loop, collision pipeline, portals            |
//!
//! What a program needs is also re-exported here, at the root: the world
//! and its definitions, handles, joints, shapes, events, queries, the
//! character mover and controller, errors
//! (and, with the `portals` feature, the portal types). [`prelude`] holds
//! the names most programs use.
//!
//! ```
//! use janus2d::prelude::*;
//! let mut world = World::new(WorldDef::default()).unwrap();
//! let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
//! let bob = world
//!     .create_body(&BodyDef::dynamic(Vec2::new(1.0, 0.0)).with_mass(1.0, 0.01))
//!     .unwrap();
//! world
//!     .create_revolute_joint(&RevoluteJointDef::new(ground, bob, Vec2::ZERO, Vec2::new(-1.0, 0.0)))
//!     .unwrap();
//! // Half a second later the bob swings through the bottom of its arc.
//! for _ in 0..30 {
//!     world.step(1.0 / 60.0).unwrap();
//! }
//! assert!(world.position(bob).unwrap().y < -0.5);
//! ```

pub use janus2d_constraints as constraints;
pub use janus2d_core as base;
pub use janus2d_world as world;

#[doc(inline)]
pub use janus2d_constraints::{DistanceJoint, DistanceJointDef, MouseJoint, MouseJointDef};
#[doc(inline)]
pub use janus2d_constraints::{FilterJoint, FilterJointDef, MotorJoint, MotorJointDef};
#[doc(inline)]
pub use janus2d_constraints::{
    Joint, JointDef, JointDefBase, JointError, JointFrame, JointKind, JointOfKind, PortalError,
    PrismaticJoint, PrismaticJointDef, RevoluteJoint, RevoluteJointDef, WeldJoint, WeldJointDef,
    WheelJoint, WheelJointDef,
};
#[doc(inline)]
pub use janus2d_core::{
    BodyDef, BodyHandle, BodyMass, BodyType, Real, Rot, SolverMode, SolverSettings, Transform, Vec2,
};
#[doc(inline)]
pub use janus2d_world::{
    Autostep, CharacterController, CollisionPlane, Ground, MoveResult, MoverCast, PlaneResult,
    PlaneSolution, clip_vector, solve_planes,
};
#[doc(inline)]
pub use janus2d_world::{
    CollisionCounters, CollisionEvents, Color, Contact, ContactPointData, DebugDraw, DrawOptions,
    Filter, HitEvent, Invariant, InvariantError, JointEvent, JointHandle, JointSet, Palette,
    PortalHop, PreSolve, PreSolveFn, QueryFilter, QueryProblem, RayHit, ShapeData, ShapeDef,
    ShapeHandle, ShapeOverlap, ShapePairEvent, SleepSettings, Snapshot, StepCounters, StepEvents,
    StepProfile, World, WorldDef, WorldError,
};
#[cfg(feature = "portals")]
#[doc(inline)]
pub use janus2d_world::{
    CrossingRole, MassModel, PlaneSide, PortalDef, PortalEvent, PortalPairDef, PortalPairHandle,
    PortalSide,
};

/// The names most programs need.
pub mod prelude {
    pub use janus2d_constraints::{DistanceJoint, DistanceJointDef, MouseJoint, MouseJointDef};
    pub use janus2d_constraints::{FilterJoint, FilterJointDef, MotorJoint, MotorJointDef};
    pub use janus2d_constraints::{
        Joint, JointDef, JointDefBase, JointFrame, JointKind, JointOfKind, PrismaticJoint,
        PrismaticJointDef, RevoluteJoint, RevoluteJointDef, WeldJoint, WeldJointDef, WheelJoint,
        WheelJointDef,
    };
    pub use janus2d_core::body::{BodyDef, BodyHandle, BodyMass, BodyType};
    pub use janus2d_core::constraint::SolverMode;
    pub use janus2d_core::geometry::{
        Capsule, ChainSegment, Circle, Polygon, Segment, Shape, make_chain,
    };
    pub use janus2d_core::math::{Real, Rot, Transform, Vec2};
    pub use janus2d_core::solver::SolverSettings;
    pub use janus2d_world::{Autostep, CharacterController, MoveResult};
    pub use janus2d_world::{
        Filter, JointEvent, JointHandle, QueryFilter, RayHit, ShapeDef, ShapeHandle, ShapeOverlap,
        StepEvents, World, WorldDef, WorldError,
    };
}

/// The README's code blocks run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
