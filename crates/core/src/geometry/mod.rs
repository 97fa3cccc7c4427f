//! Collision geometry: shapes, mass properties, bounding boxes and contact
//! manifolds. Pure functions of shapes and transforms; no world state.
//!
//! - [`shapes`]: [`Circle`], [`Capsule`], [`Polygon`] (convex, ≤ 8 vertices,
//!   optionally rounded), [`Segment`], one-sided [`ChainSegment`], the
//!   [`Shape`] enum, [`Polygon::from_hull`], [`make_chain`], [`GeometryError`]
//!   and the tolerances ([`LINEAR_SLOP`], [`SPECULATIVE_DISTANCE`], …).
//! - [`mass`]: [`MassData`], [`Shape::compute_mass`], [`Shape::area`] (exact,
//!   rounded shapes included).
//! - [`query`]: [`Shape::compute_aabb`], [`Shape::support_extent`],
//!   [`Shape::scaled`], [`Shape::area_in_front`] (exact).
//! - [`manifold`]: [`collide`] → [`Manifold`].
//! - [`ray`]: [`Shape::ray_cast`] → [`CastHit`] (fraction, point, normal).
//! - [`distance`]: [`ShapeProxy`], GJK [`shape_distance`] (closest points),
//!   [`shapes_overlap`], [`shape_cast`] (a shape swept along a translation).
//! - [`toi`]: [`Sweep`], [`time_of_impact`] → [`ToiOutput`] (continuous
//!   collision of two moving, turning shapes), [`shape_extent`].
//!
//! # Manifold conventions
//!
//! The normal is a world unit vector from A to B. Each point is midway between
//! the two surfaces; `anchor_a = point - xf_a.p`, `anchor_b = point - xf_b.p`
//! (world-aligned). `separation < 0` is overlap; points are reported while
//! `separation < speculative_distance`. Feature ids are
//! `(feature_a << 8) | feature_b` ([`feature_id`]).
//!
//! # Which routine handles which pair
//!
//! Rows are shape A, columns shape B. "(swap)" means the pair is computed with
//! A and B exchanged and the result [`Manifold::flipped`].
//!
//! | A \ B        | Circle                 | Capsule              | Polygon              | Segment              | ChainSegment                  |
//! |--------------|------------------------|----------------------|----------------------|----------------------|-------------------------------|
//! | Circle       | circles                | capsule–circle (swap)| polygon–circle (swap)| capsule–circle (swap)| chain–circle (swap)           |
//! | Capsule      | capsule–circle         | capsules             | polygons (2-gon A)   | capsules (r_B = 0)   | chain–polygon (swap)          |
//! | Polygon      | polygon–circle         | polygons (2-gon B)   | polygons             | polygons (2-gon B)   | chain–polygon (swap)          |
//! | Segment      | capsule–circle (r = 0) | capsules (r_A = 0)   | polygons (2-gon A)   | capsules (r = 0)     | chain–polygon (swap)          |
//! | ChainSegment | chain–circle           | chain–polygon        | chain–polygon        | chain–polygon        | chains                        |
//!
//! - *circles*: centre distance; coincident centres use A's local +y.
//! - *capsule–circle*: closest point on the core, then as circles.
//! - *polygon–circle*: edge of greatest separation, vertex or face region.
//! - *capsules*: closest points of the two cores; two points when the cores
//!   are nearly parallel and overlap.
//! - *polygons*: SAT reference face (A preferred), incident edge clipping or a
//!   vertex–vertex point; capsules and segments enter as 2-vertex polygons
//!   ([`Polygon::make_capsule`]).
//! - *chain–…*: one-sided (nothing when the other shape's centre is behind),
//!   ghost vertices decide who owns a shared vertex, and normals that would
//!   snag on an internal vertex are dropped (see [`ChainSegment`]).

pub mod aabb;
pub mod distance;
pub mod manifold;
pub mod mass;
pub mod query;
pub mod ray;
pub mod shapes;
pub mod toi;

pub use aabb::Aabb;
pub use distance::{
    CAST_MAX_ITERATIONS, CAST_TOLERANCE, DistanceOutput, GJK_MAX_ITERATIONS, ShapeProxy,
    shape_cast, shape_distance, shapes_overlap,
};
pub use manifold::{
    CAPSULE_PARALLEL_SINE, CHAIN_FACE_SINE, Manifold, ManifoldPoint, REFERENCE_FACE_TOLERANCE,
    collide, collide_with_clearance, feature_id,
};
pub use mass::MassData;
pub use ray::{CastHit, RayInput};
pub use shapes::{
    Capsule, ChainSegment, Circle, GeometryError, LINEAR_SLOP, MAX_POLYGON_VERTICES, Polygon,
    SPECULATIVE_DISTANCE, Segment, Shape, WELD_DISTANCE, make_chain,
};
pub use toi::{
    ShapeExtent, Sweep, TOI_MAX_ITERATIONS, ToiOutput, ToiState, shape_extent, time_of_impact,
};
