//! # janus2d-world
//!
//! The world: the stepping loop and the stages it calls, each owning its
//! data.
//!
//! The public surface is [`World`] and the types re-exported at this
//! crate's root; [`world`], [`query`], [`portal`], [`debug_draw`] and
//! [`dynamic_tree`], [`aperture`], [`mover`] and [`character`] are public modules, the stages are private to the crate:
//!
//! | module           | what                                                     |
//! |------------------|----------------------------------------------------------|
//! | [`world`]        | [`World`], [`WorldDef`]: the public API split by topic (bodies, shapes, joints, queries, events) and the step |
//! | `error`          | [`WorldError`], the typed errors of the API               |
//! | `shapes`         | the shape store: geometry, material, filter, body → shapes |
//! | [`debug_draw`]   | the [`DebugDraw`] trait, draw flags and colours, the drawing walk |
//! | `continuous`     | continuous collision: fast bodies swept to their time of impact |
//! | `contacts`       | the contact life cycle; awake and sleeping contacts, body → contacts |
//! | `narrowphase`    | manifolds of awake contacts, updated in place             |
//! | `contact_build`  | contact constraints from the narrowphase's hand-off (colours, clusters, lanes) |
//! | `collision`      | the collision stage: shapes + broadphase + contacts + events |
//! | `broadphase`     | pair finding over two dynamic trees                      |
//! | [`dynamic_tree`] | the dynamic AABB tree (insert, remove, rotate, query)     |
//! | `joints`         | the joint set: slots, one storage for every kind, body → joints, no-collide pairs |
//! | `islands`        | sleep timers and islands; sleeping islands leave every per-step loop |
//! | [`portal`]       | portal pairs, crossings, clones                           |
//! | [`aperture`]     | aperture clipping: the geometry the portal stage hands the narrowphase and continuous collision |
//! | `profile`        | per-stage timings and work counters                      |
//! | [`query`]        | scene queries: rays, shape casts, overlaps, distances    |
//! | [`mover`]        | the character mover's planes: solve them, clip a velocity (`World::cast_mover`, `World::collide_mover`) |
//! | [`character`]    | [`CharacterController`]: slope limit, autostep, snap to ground, one-way and moving platforms |
//! | `hash`           | the state hash of determinism checks                     |
//! | `snapshot`       | [`Snapshot`]: `World::snapshot` and `World::restore`      |
//! | `validate`       | [`World::validate`]: every cross-structure invariant     |
//!
//! See `docs/architecture.md` for the stage table.

pub mod aperture;
pub(crate) mod broadphase;
pub mod chains;
pub mod character;
pub(crate) mod collision;
pub(crate) mod contact_build;
pub(crate) mod contacts;
pub(crate) mod continuous;
pub mod debug_draw;
pub mod dynamic_tree;
pub(crate) mod error;
pub(crate) mod hash;
pub(crate) mod hooks;
pub(crate) mod islands;
pub(crate) mod joints;
pub(crate) mod key_map;
pub mod mover;
pub(crate) mod narrowphase;
pub mod portal;
pub(crate) mod profile;
pub mod query;
#[cfg(feature = "serde")]
mod serde_maps;
pub(crate) mod shapes;
pub(crate) mod snapshot;
mod stores;
pub(crate) mod validate;
pub mod world;

pub use chains::{ChainDef, ChainHandle, SurfaceMaterial};
pub use character::{Autostep, CharacterController, Ground, MoveResult};
pub use contacts::{
    CollisionEvents, Contact, ContactBeginEvent, ContactForceEvent, ContactPointData,
    EventManifold, HitEvent, SensorEvent, ShapePairEvent,
};
pub use continuous::ContinuousCounters;
pub use debug_draw::{Color, DebugDraw, DrawOptions, Palette};
pub use error::WorldError;
pub use hooks::{MixFn, PairFilterFn};
pub use islands::SleepSettings;
pub use joints::{JointEvent, JointHandle, JointKind, JointSet};
pub use mover::{
    CollisionPlane, MoverCast, MoverCrossing, PlaneResult, PlaneSolution, clip_vector, solve_planes,
};
pub use narrowphase::{PreSolve, PreSolveFn};
#[cfg(feature = "portals")]
pub use portal::{
    CrossingRole, MassModel, PlaneSide, PortalDef, PortalEvent, PortalPairDef, PortalPairHandle,
    PortalSide,
};
pub use profile::{CollisionCounters, EventWork, StepCounters, StepProfile};
pub use query::{
    PointProjection, PortalHop, QueryFilter, QueryPredicate, QueryProblem, RayHit, ShapeOverlap,
};
pub use shapes::{Filter, ShapeData, ShapeDef, ShapeHandle};
pub use snapshot::Snapshot;
#[cfg(feature = "serde")]
pub use snapshot::bytes::{SNAPSHOT_MAGIC, SNAPSHOT_VERSION, SnapshotError};
pub use validate::{Invariant, InvariantError};
pub use world::{BodyMoveEvent, ExplosionDef, StepEvents, TEAM_MIN_WORK, World, WorldDef};

/// Helpers shared by the crate's property tests.
#[cfg(test)]
pub(crate) mod test_support {
    use proptest::test_runner::RngSeed;

    /// `seed` when `PROPTEST_RNG_SEED` fixed it, else `Fixed(fixed)`: a
    /// property's cases are the same on every run unless asked otherwise.
    /// For `proptest!` blocks:
    /// `rng_seed: fixed_unless_asked(ProptestConfig::default().rng_seed, N)`.
    pub(crate) fn fixed_unless_asked(seed: RngSeed, fixed: u64) -> RngSeed {
        match seed {
            RngSeed::Random => RngSeed::Fixed(fixed),
            asked => asked,
        }
    }
}
