//! Portals: linked apertures that bodies pass through, cloned and scaled.
//!
//! | file | what |
//! |------|------|
//! | `stage.rs` | pairs, crossings, clones, handover, weights; the portal API on `World`, and where the world applies the stage's commands (with the `portals` feature) |
//! | `crossing.rs` | the crossing stage's decisions, read from bodies, shapes and the broadphase, returned as commands |
//! | `noop.rs` | the stage's twin without the feature: no state, every step call does nothing |
//! | `coupling.rs` | joints and portal rows solved together while a crossing copy carries a joint |
//! | `clipping` | (re-export of the collision-side `crate::aperture`) apertures as geometry: manifolds clipped to a wall's solid parts, copies' far sides, ignored pairs; the stage fills it, the narrowphase and continuous collision read it |
//!
//! The world calls the stage in the same places with or without the
//! feature; only which twin is compiled changes.

/// Aperture clipping is collision-side geometry ([`crate::aperture`]):
/// the portal stage builds its [`ContactClipping`] each step.
pub(crate) use crate::aperture as clipping;
pub(crate) mod coupling;
#[cfg(feature = "portals")]
mod crossing;
#[cfg(not(feature = "portals"))]
mod noop;
#[cfg(feature = "portals")]
mod stage;

#[cfg(not(feature = "portals"))]
pub(crate) use noop::PortalStage;
#[cfg(feature = "portals")]
pub(crate) use stage::PortalStage;
#[cfg(feature = "portals")]
pub use stage::{
    CrossingRole, F_JOINTED, F_MIN, MassModel, PlaneSide, PortalCounters, PortalDef, PortalEvent,
    PortalPairDef, PortalPairHandle, PortalSide,
};
