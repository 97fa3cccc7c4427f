//! Collision geometry: shapes, mass properties, bounding boxes and contact
//! manifolds. Pure functions of shapes and transforms; no world state.

pub mod aabb;

pub use aabb::Aabb;
