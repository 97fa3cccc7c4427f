//! # janus2d-core
//!
//! Bodies, integration, the sequential-impulse solver and the constraint
//! trait that reports J, K and bias.
#![doc = "See `docs/architecture.md` for the crate graph and the step pipeline."]

pub mod geometry;
pub mod math;

pub use math::{Real, Rot, Transform, Vec2};
