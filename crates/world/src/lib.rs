//! # janus2d-world
//!
//! The world: the stepping loop, bodies, joints, the collision pipeline and
//! portals.
//!
//! | module        | what                                              |
//! |---------------|---------------------------------------------------|
//! | [`world`]     | [`World`], [`WorldDef`], handles, the step        |
//! | [`error`]     | [`WorldError`], the typed errors of the API        |

pub mod error;
pub mod world;

pub use error::WorldError;
pub use world::{JointHandle, StepEvents, World, WorldDef};
