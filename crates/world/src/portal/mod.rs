//! Portals: linked apertures that bodies pass through, cloned and scaled.
//!
//! | file | what |
//! |------|------|
//! | `stage.rs` | the stage's types and state (pairs, crossings, constraints, events); the pair API's logic and the crossing stage (start, hand over, cancel, weigh, carry joints) as verbs over the stores they are passed (with the `portals` feature) |
//! | `crossing.rs` | the crossing stage's decisions, read from bodies, shapes and the broadphase; the commands by which the stage asks the world for each change of structure |
//! | `noop.rs` | the stage's twin without the feature: no state, the same verbs, each does nothing |
//! | `coupling.rs` | joints and portal rows solved together while a crossing copy carries a joint |
//! | `clipping` | (re-export of the collision-side `crate::aperture`) apertures as geometry: manifolds clipped to a wall's solid parts, copies' far sides, ignored pairs; the stage fills it, the narrowphase and continuous collision read it |
//!
//! The stage knows nothing of the world: the public portal API
//! (`world/portals.rs`) and the step (`world/step.rs`) pass it the stores
//! it reads and writes (`Stores`: bodies, joints, collision, islands). It
//! writes masses, velocities and joint impulses itself; every change of
//! structure (a clone created or destroyed, a shape added, a joint
//! re-pointed or disabled, two bodies' identities swapped, a body woken)
//! goes through a store-level operation the world defines in
//! `world/internal.rs`: a `PortalCommand`
//! applied at once, in the order the stage emits it, or, for the clone's
//! new body, whose handle the stage needs at once, `Stores::insert_body`.
//!
//! The world calls the stage in the same places with or without the
//! feature; only which twin is compiled changes.

// Aperture clipping is collision-side geometry (`crate::aperture`): the
// portal stage builds its `ContactClipping` each step.
pub(crate) use crate::aperture as clipping;
pub(crate) mod coupling;
#[cfg(feature = "portals")]
mod crossing;
#[cfg(not(feature = "portals"))]
mod noop;
#[cfg(feature = "portals")]
mod stage;

#[cfg(feature = "portals")]
pub(crate) use crossing::PortalCommand;
#[cfg(not(feature = "portals"))]
pub(crate) use noop::PortalStage;
#[cfg(feature = "portals")]
pub(crate) use stage::PortalStage;
#[cfg(feature = "portals")]
pub use stage::{
    CrossingRole, F_JOINTED, F_MIN, MassModel, PlaneSide, PortalCounters, PortalDef, PortalEvent,
    PortalPairDef, PortalPairHandle, PortalSide,
};
