//! # janus2d-world
//!
//! The world: the stepping loop and the stages it calls, each owning its
//! data.
//!
//! | module           | what                                                     |
//! |------------------|----------------------------------------------------------|
//! | [`world`]        | [`World`], [`WorldDef`]: the public API split by topic (bodies, shapes, joints, queries, events) and the step |
//! | [`error`]        | [`WorldError`], the typed errors of the API               |
//! | [`shapes`]       | the shape store: geometry, material, filter, body → shapes |
//! | [`debug_draw`]   | the [`DebugDraw`] trait, draw flags and colours, the drawing walk |
//! | [`continuous`]   | continuous collision: fast bodies swept to their time of impact |
//! | [`contacts`]     | the contact life cycle; awake and sleeping contacts, body → contacts |
//! | [`narrowphase`]  | manifolds of awake contacts; contact constraints          |
//! | [`collision`]    | the collision stage: shapes + broadphase + contacts + events |
//! | [`broadphase`]   | pair finding over two dynamic trees                      |
//! | [`dynamic_tree`] | the dynamic AABB tree (insert, remove, rotate, query)     |
//! | [`joints`]       | the joint set: slots, per-type storage, body → joints, no-collide pairs |
//! | [`islands`]      | sleep timers and islands; sleeping islands leave every per-step loop |
//! | [`portal`]       | portal pairs, crossings, clones, aperture clipping        |
//! | [`profile`]      | per-stage timings and work counters                      |
//! | [`query`]        | scene queries: rays, shape casts, overlaps, distances    |
//! | [`hash`]         | the state hash of determinism checks                     |
//! | [`snapshot`]     | [`Snapshot`]: `World::snapshot` and `World::restore`      |
//! | [`validate`]     | [`World::validate`]: every cross-structure invariant     |
//!
//! See `docs/architecture.md` for the stage table.

pub mod broadphase;
pub mod collision;
pub mod contacts;
pub mod continuous;
pub mod debug_draw;
pub mod dynamic_tree;
pub mod error;
pub mod hash;
pub mod islands;
pub mod joints;
pub mod narrowphase;
pub mod portal;
pub mod profile;
pub mod query;
pub mod shapes;
pub mod snapshot;
mod stores;
pub mod validate;
pub mod world;

pub use collision::CollisionCounters;
pub use contacts::{CollisionEvents, Contact, ContactPointData, ShapePairEvent};
pub use continuous::ContinuousCounters;
pub use debug_draw::{Color, DebugDraw, DrawOptions, Palette};
pub use error::WorldError;
pub use islands::SleepSettings;
pub use joints::{JointHandle, JointKind, JointSet};
pub use narrowphase::{PreSolve, PreSolveFn};
#[cfg(feature = "portals")]
pub use portal::{
    CrossingRole, MassModel, PlaneSide, PortalDef, PortalEvent, PortalPairDef, PortalPairHandle,
    PortalSide,
};
pub use profile::{StepCounters, StepProfile};
pub use query::{PortalHop, QueryFilter, QueryProblem, RayHit, ShapeOverlap};
pub use shapes::{Filter, ShapeData, ShapeDef, ShapeHandle};
pub use snapshot::Snapshot;
#[cfg(feature = "serde")]
pub use snapshot::bytes::{SNAPSHOT_MAGIC, SNAPSHOT_VERSION, SnapshotError};
pub use validate::{Invariant, InvariantError};
pub use world::{StepEvents, World, WorldDef};
