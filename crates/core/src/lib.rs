//! # janus2d-core
//!
//! Bodies, integration, the sequential-impulse solver and the constraint
//! trait that reports J, K and bias.
//!
//! | module         | what                                                        |
//! |----------------|-------------------------------------------------------------|
//! | [`math`]       | the scalar alias, vectors, rotations, transforms, small solves |
//! | [`body`]       | body definitions, generational handles, hot/cold storage    |
//! | [`softness`]   | the one softness type of every soft row                    |
//! | [`constraint`] | the constraint trait, rows, blocks, the step context        |
//! | [`solver`]     | the soft step and the PGS baseline                          |
//! | [`parallel`]   | the step's worker team (uses `unsafe`, with its proof)      |
//! | [`hint`]       | a cache prefetch hint (the other module with `unsafe`)      |
//! | [`geometry`]   | shapes, mass properties, bounding boxes, manifolds          |
//! | [`limits`]     | the stated finite range of every input value                |
//! | [`handle`]     | one generational handle type for every kind of object       |
//! | [`slots`]      | generational slots behind handles                           |
//! | [`union_find`] | union–find over dense indices (islands, joint forests)      |
//!
//! See `docs/architecture.md` for the crate graph and the step pipeline.

pub mod body;
pub mod constraint;
pub mod contact_input;
pub mod geometry;
pub mod graph;
pub mod handle;
pub mod hint;
pub mod limits;
pub mod material;
pub mod math;
pub mod parallel;
pub mod slots;
pub mod softness;
pub mod solver;
pub mod team_choice;
pub mod union_find;

pub use body::{BodyDef, BodyHandle, BodyMass, BodySet, BodyState, BodyType, InvMass, MotionLocks};
pub use constraint::{Constraint, ConstraintBatch, ConstraintRows, SolverMode, StepContext};
pub use handle::{Handle, HandleError};
pub use math::{Real, Rot, Transform, Vec2};
pub use softness::Softness;
pub use solver::SolverSettings;
