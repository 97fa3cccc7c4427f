//! # janus2d
//!
//! A 2D rigid-body physics engine whose signature is the portal. This crate
//! is the one a program depends on: everything a program touches is
//! re-exported here and documented on these pages (`cargo doc --open -p
//! janus2d`).
//!
//! ## Where things are
//!
//! | you want                              | look at                                                    |
//! |---------------------------------------|------------------------------------------------------------|
//! | the world: create, step, read back    | [`World`], [`WorldDef`], [`WorldError`]                     |
//! | bodies                                | [`BodyDef`], [`BodyHandle`], [`BodyType`], [`BodyMass`]     |
//! | shapes and their material             | [`Polygon`], [`Circle`], [`Capsule`], [`Segment`], [`make_chain`], [`ShapeDef`], [`Filter`]; chains: [`ChainDef`], [`ChainHandle`], [`SurfaceMaterial`], [`World::create_chain`] |
//! | joints (eight kinds)                  | [`JointDef`], [`World::create_joint`], [`RevoluteJointDef`] and the other `…JointDef`s |
//! | scene queries: rays, casts, overlaps  | [`query`], [`QueryFilter`], [`RayHit`], [`World::cast_ray_closest`] |
//! | a character mover and controller      | [`CharacterController`], [`World::cast_mover`], [`World::collide_mover`], [`solve_planes`], [`clip_vector`] |
//! | events after a step                   | [`StepEvents`] ([`World::events`]): [`CollisionEvents`] (contact begin with manifold, end, sensor, [`HitEvent`], contact force), [`JointEvent`], [`PortalEvent`], body move events |
//! | changing contacts before the solve    | [`PreSolve`], [`World::set_pre_solve`], [`World::set_pair_filter`] |
//! | surface materials                     | [`ShapeDef`] (`rolling_resistance`, `tangent_speed`, `friction_combine`, `user_material_id`), [`CombineRule`], [`World::set_friction_callback`] |
//! | portals (feature `portals`, default)  | [`portal`], [`PortalPairDef`], [`PortalDef`], [`World::create_portal_pair`] |
//! | saving and restoring a world          | [`Snapshot`], [`World::snapshot`], [`World::restore`]       |
//! | drawing a world                       | [`debug_draw`], [`DebugDraw`], [`DrawOptions`], [`World::debug_draw`] |
//! | pictures: PNG, SVG, GIF (feature `render`, default) | [`render`]: [`render::Raster`], [`render::Svg`], [`render::GifWriter`], [`render::Camera`] |
//! | solver settings                       | [`SolverSettings`], [`SolverMode`], [`SleepSettings`]       |
//! | timings and counters                  | [`StepProfile`], [`StepCounters`]                           |
//! | limits on inputs                      | [`limits`]                                                  |
//!
//! [`prelude`] holds the names most programs use:
//! `use janus2d::prelude::*;`.
//!
//! The engine is split into crates, each also reachable here whole:
//! [`base`] (`janus2d-core`: math, bodies, geometry, the solver),
//! [`constraints`] (`janus2d-constraints`: contacts, joints, the portal
//! constraint) and [`world`] (`janus2d-world`: the world and its stages).
//! Examples on the pages of those crates' items name them by their crate
//! (`janus2d_world::World`, `janus2d_core::geometry::Polygon`); from a
//! program write `janus2d::World`, `janus2d::Polygon` (or
//! `janus2d::world::…`, `janus2d::base::…`). docs/guide.md in the
//! repository builds a small game step by step with these names.
//!
//! ## A pendulum
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
//!
//! ## Shapes, a query and the events of a step
//!
//! ```
//! use janus2d::prelude::*;
//! use janus2d::ShapeDef;
//!
//! let mut world = World::new(WorldDef::default()).unwrap();
//! let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5))).unwrap();
//! world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(10.0, 0.5)).unwrap();
//! let ball = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 2.0))).unwrap();
//! let circle = Circle::new(Vec2::ZERO, 0.5).unwrap();
//! world.create_shape(ball, &ShapeDef::default(), circle).unwrap();
//!
//! // A ray straight down from above finds the ball first.
//! let hit = world
//!     .cast_ray_closest(Vec2::new(0.0, 10.0), Vec2::new(0.0, -20.0), &QueryFilter::default())
//!     .unwrap()
//!     .expect("the ray meets the ball");
//! assert_eq!(hit.body, ball);
//!
//! // The ball lands: a contact begins.
//! let mut landed = false;
//! for _ in 0..60 {
//!     world.step(1.0 / 60.0).unwrap();
//!     landed |= !world.events().collision.contact_begin.is_empty();
//! }
//! assert!(landed);
//! ```
//!
//! ## A snapshot and a picture
//!
//! ```
//! use janus2d::prelude::*;
//! use janus2d::DrawOptions;
//!
//! let mut world = World::new(WorldDef::default()).unwrap();
//! let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
//! world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
//! let saved = world.snapshot();
//! world.step(1.0 / 60.0).unwrap();
//! let after_one = world.position(b).unwrap();
//! world.restore(&saved);
//! world.step(1.0 / 60.0).unwrap();
//! assert_eq!(world.position(b).unwrap(), after_one); // bit for bit
//!
//! # #[cfg(feature = "render")] {
//! use janus2d::render::{Camera, Raster};
//! let mut picture = Raster::new(Camera::fit_world(&world, 64, 64)).unwrap();
//! picture.draw_world(&world, &DrawOptions::default());
//! assert_eq!(&picture.encode_png().unwrap()[1..4], b"PNG");
//! # }
//! ```
//!
//! ## Features
//!
//! | feature    | default | what                                                        |
//! |------------|---------|-------------------------------------------------------------|
//! | `portals`  | yes     | portal pairs, crossings and their events                    |
//! | `render`   | yes     | [`render`]: PNG, SVG and GIF pictures of a world            |
//! | `f64`      | no      | [`Real`] is `f64` instead of `f32`                          |
//! | `parallel` | no      | the solver and most of collision on rayon threads           |
//! | `serde`    | no      | [`Snapshot`] to bytes and back                              |

#[doc(inline)]
pub use janus2d_constraints as constraints;
#[doc(inline)]
pub use janus2d_core as base;
#[doc(inline)]
pub use janus2d_world as world;

/// Pictures of a world (the `janus2d-render` crate, feature `render`):
/// PNG frames, SVG documents, GIF clips and a camera, all drawn through
/// [`DebugDraw`].
#[cfg(feature = "render")]
#[doc(inline)]
pub use janus2d_render as render;

#[doc(inline)]
pub use janus2d_core::geometry;
#[doc(inline)]
pub use janus2d_core::limits;
#[doc(inline)]
pub use janus2d_world::{debug_draw, portal, query};

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
pub use janus2d_constraints::{PortalConstraint, PortalMap};
#[doc(inline)]
pub use janus2d_core::geometry::{
    Aabb, Capsule, ChainSegment, Circle, GeometryError, Polygon, Segment, Shape, make_chain,
};
#[doc(inline)]
pub use janus2d_core::material::CombineRule;
#[doc(inline)]
pub use janus2d_core::solver::SolverProfile;
#[doc(inline)]
pub use janus2d_core::{
    BodyDef, BodyHandle, BodyMass, BodyType, MotionLocks, Real, Rot, SolverMode, SolverSettings,
    Transform, Vec2,
};
#[cfg(feature = "serde")]
#[doc(inline)]
pub use janus2d_world::SnapshotError;
#[doc(inline)]
pub use janus2d_world::aperture::ContactClipping;
#[cfg(feature = "portals")]
#[doc(inline)]
pub use janus2d_world::portal::PortalCounters;
#[doc(inline)]
pub use janus2d_world::{
    Autostep, CharacterController, CollisionPlane, Ground, MoveResult, MoverCast, MoverCrossing,
    PlaneResult, PlaneSolution, clip_vector, solve_planes,
};
#[doc(inline)]
pub use janus2d_world::{ChainDef, ChainHandle, SurfaceMaterial};
#[doc(inline)]
pub use janus2d_world::{
    CollisionCounters, CollisionEvents, Color, Contact, ContactPointData, ContinuousCounters,
    DebugDraw, DrawOptions, EventWork, ExplosionDef, Filter, HitEvent, Invariant, InvariantError,
    JointEvent, JointHandle, JointSet, MixFn, PairFilterFn, Palette, PointProjection, PortalHop,
    PreSolve, PreSolveFn, QueryFilter, QueryPredicate, QueryProblem, RayHit, ShapeData, ShapeDef,
    ShapeHandle, ShapeOverlap, ShapePairEvent, SleepSettings, Snapshot, StepCounters, StepEvents,
    StepProfile, World, WorldDef, WorldError,
};
#[cfg(feature = "portals")]
#[doc(inline)]
pub use janus2d_world::{
    CrossingRole, MassModel, PlaneSide, PortalDef, PortalEvent, PortalPairDef, PortalPairHandle,
    PortalSide,
};

/// The names most programs need: `use janus2d::prelude::*;`.
pub mod prelude {
    pub use janus2d_constraints::{DistanceJoint, DistanceJointDef, MouseJoint, MouseJointDef};
    pub use janus2d_constraints::{FilterJoint, FilterJointDef, MotorJoint, MotorJointDef};
    pub use janus2d_constraints::{
        Joint, JointDef, JointDefBase, JointFrame, JointKind, JointOfKind, PrismaticJoint,
        PrismaticJointDef, RevoluteJoint, RevoluteJointDef, WeldJoint, WeldJointDef, WheelJoint,
        WheelJointDef,
    };
    pub use janus2d_core::body::{BodyDef, BodyHandle, BodyMass, BodyType, MotionLocks};
    pub use janus2d_core::constraint::SolverMode;
    pub use janus2d_core::geometry::{
        Capsule, ChainSegment, Circle, Polygon, Segment, Shape, make_chain,
    };
    pub use janus2d_core::material::CombineRule;
    pub use janus2d_core::math::{Real, Rot, Transform, Vec2};
    pub use janus2d_core::solver::SolverSettings;
    pub use janus2d_world::{Autostep, CharacterController, MoveResult};
    pub use janus2d_world::{ChainDef, ChainHandle, SurfaceMaterial};
    pub use janus2d_world::{
        ExplosionDef, Filter, JointEvent, JointHandle, PointProjection, QueryFilter, RayHit,
        ShapeDef, ShapeHandle, ShapeOverlap, StepEvents, World, WorldDef, WorldError,
    };
}

/// The README's code blocks run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
