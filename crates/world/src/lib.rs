//! # janus2d-world
//!
//! The world: the stepping loop, bodies, joints, the collision pipeline and
//! portals.
//!
//! | module        | what                                              |
//! |---------------|---------------------------------------------------|
//! | [`world`]     | [`World`], [`WorldDef`], handles, the step        |
//! | [`error`]     | [`WorldError`], the typed errors of the API        |
//! | [`collision`] | shapes, contacts, events                          |
//! | [`broadphase`]| pair finding over two dynamic trees               |
//! | [`dynamic_tree`]| the dynamic AABB tree: insert, remove, query    |
//! | [`portals`]   | portal pairs, crossings, clones, handover         |
//! | [`sleep`]     | resting islands leave the solver                  |
//! | [`profile`]   | per-stage timings and work counters               |

pub mod broadphase;
pub mod collision;
pub mod dynamic_tree;
pub mod error;
#[cfg(feature = "portals")]
pub mod portals;
pub mod profile;
pub mod sleep;
pub mod world;

pub use collision::{CollisionEvents, Filter, ShapeDef, ShapeHandle};
pub use error::WorldError;
#[cfg(feature = "portals")]
pub use portals::{MassModel, PortalDef, PortalEvent, PortalPairDef, PortalPairHandle};
pub use profile::{StepCounters, StepProfile};
pub use sleep::SleepSettings;
pub use world::{JointHandle, StepEvents, World, WorldDef};
