//! Scene queries: rays, shape casts, overlaps and distances (the logic
//! is in `crate::query`; these check input and build its context).

use super::*;

impl World {
    // ----- scene queries (logic in query.rs) ---------------------------------

    pub(super) fn query_context(
        &self,
        filter: &crate::query::QueryFilter,
    ) -> crate::query::QueryContext<'_> {
        let owner = self.bodies.owner();
        crate::query::QueryContext {
            shapes: &self.collision.shapes,
            broadphase: &self.collision.broadphase,
            bodies: &self.bodies,
            owner,
            apertures: if filter.through_portals {
                self.portals.query_apertures(&self.bodies, owner)
            } else {
                Vec::new()
            },
        }
    }

    /// Casts the ray `origin + s · translation`, `s ∈ [0, 1]`, and hands
    /// every hit to `callback`, nearest first; the callback returns `-1` to
    /// ignore the hit, `0` to stop, a fraction to clip the ray, `1` to go
    /// on (see [`crate::query`]). Errors: a non-finite origin or
    /// translation, a zero translation ([`WorldError::BadQuery`]).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// for x in [2.0, 4.0] {
    ///     let b = world.create_body(&BodyDef::fixed(Vec2::new(x, 0.0))).unwrap();
    ///     world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// }
    /// let mut fractions = Vec::new();
    /// world.cast_ray_with(Vec2::ZERO, Vec2::new(10.0, 0.0), &QueryFilter::default(), |hit| {
    ///     fractions.push(hit.fraction);
    ///     1.0 // go on: every hit
    /// }).unwrap();
    /// assert_eq!(fractions.len(), 2);
    /// assert!((fractions[0] - 0.15).abs() < 1e-6 && (fractions[1] - 0.35).abs() < 1e-6);
    /// ```
    pub fn cast_ray_with<F: FnMut(&crate::query::RayHit) -> Real>(
        &self,
        origin: Vec2,
        translation: Vec2,
        filter: &crate::query::QueryFilter,
        callback: F,
    ) -> Result<(), WorldError> {
        let ctx = self.query_context(filter);
        crate::query::cast_ray(&ctx, origin, translation, filter, callback)
    }

    /// The nearest hit of the ray `origin + s · translation`, `s ∈ [0, 1]`,
    /// or `None`. Errors as [`cast_ray_with`](Self::cast_ray_with).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Circle;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::fixed(Vec2::new(0.0, 5.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, 1.0).unwrap()).unwrap();
    /// let hit = world
    ///     .cast_ray_closest(Vec2::ZERO, Vec2::new(0.0, 10.0), &QueryFilter::default())
    ///     .unwrap()
    ///     .unwrap();
    /// assert_eq!(hit.body, b);
    /// assert!((hit.point - Vec2::new(0.0, 4.0)).length() < 1e-5);
    /// assert!((hit.normal - Vec2::new(0.0, -1.0)).length() < 1e-5);
    /// ```
    pub fn cast_ray_closest(
        &self,
        origin: Vec2,
        translation: Vec2,
        filter: &crate::query::QueryFilter,
    ) -> Result<Option<crate::query::RayHit>, WorldError> {
        let mut best = None;
        self.cast_ray_with(origin, translation, filter, |hit| {
            best = Some(*hit);
            hit.fraction
        })?;
        Ok(best)
    }

    /// Sweeps `shape`, placed by `transform`, along `translation` and hands
    /// every shape it meets to `callback` (nearest first, same return rule
    /// as [`cast_ray_with`](Self::cast_ray_with)). A hit's point and normal
    /// are on the surface of the shape hit; shapes the swept shape already
    /// overlaps at the start are hits at fraction 0. Errors: an invalid
    /// shape, a non-finite transform or translation, a zero translation, a
    /// transform whose rotation is not unit length
    /// ([`QueryProblem::NotUnitRotation`](crate::QueryProblem::NotUnitRotation);
    /// within [`UNIT_ROTATION_TOLERANCE`](janus2d_core::limits::UNIT_ROTATION_TOLERANCE)
    /// it is normalised).
    pub fn cast_shape_with<F: FnMut(&crate::query::RayHit) -> Real>(
        &self,
        shape: &Shape,
        transform: &Transform,
        translation: Vec2,
        filter: &crate::query::QueryFilter,
        callback: F,
    ) -> Result<(), WorldError> {
        let ctx = self.query_context(filter);
        crate::query::cast_shape(&ctx, shape, transform, translation, filter, callback)
    }

    /// The first shape that `shape`, placed by `transform` and swept along
    /// `translation`, meets, or `None`. Errors as
    /// [`cast_shape_with`](Self::cast_shape_with).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Transform, Vec2};
    /// use janus2d_core::geometry::{Circle, Polygon, Shape};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let wall = world.create_body(&BodyDef::fixed(Vec2::new(6.0, 0.0))).unwrap();
    /// world.create_shape(wall, &ShapeDef::default(), Polygon::make_box(1.0, 1.0)).unwrap();
    /// let ball = Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap());
    /// let hit = world
    ///     .cast_shape_closest(&ball, &Transform::IDENTITY, Vec2::new(10.0, 0.0), &QueryFilter::default())
    ///     .unwrap()
    ///     .unwrap();
    /// // The ball's centre stops at x = 4.5, touching the face at x = 5.
    /// assert!((hit.fraction - 0.45).abs() < 1e-3);
    /// assert!((hit.normal - Vec2::new(-1.0, 0.0)).length() < 1e-3);
    /// ```
    pub fn cast_shape_closest(
        &self,
        shape: &Shape,
        transform: &Transform,
        translation: Vec2,
        filter: &crate::query::QueryFilter,
    ) -> Result<Option<crate::query::RayHit>, WorldError> {
        let mut best = None;
        self.cast_shape_with(shape, transform, translation, filter, |hit| {
            best = Some(*hit);
            hit.fraction
        })?;
        Ok(best)
    }

    /// Hands `callback` every shape whose surface meets `aabb` (exact: a
    /// fat box that meets it is not enough), in shape slot order, until it
    /// returns `false`. Errors: a non-finite or inverted box.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::{Aabb, Circle};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.5).unwrap()).unwrap();
    /// let near = Aabb::new(Vec2::new(0.51, -0.1), Vec2::new(1.0, 0.1)); // 1 cm off the ball
    /// let mut found = 0;
    /// world.overlap_aabb(&near, &QueryFilter::default(), |_| { found += 1; true }).unwrap();
    /// assert_eq!(found, 0);
    /// ```
    pub fn overlap_aabb<F: FnMut(crate::query::ShapeOverlap) -> bool>(
        &self,
        aabb: &janus2d_core::geometry::Aabb,
        filter: &crate::query::QueryFilter,
        callback: F,
    ) -> Result<(), WorldError> {
        let ctx = self.query_context(filter);
        crate::query::overlap_aabb(&ctx, aabb, filter, callback)
    }

    /// Hands `callback` every shape that touches or overlaps `shape` placed
    /// by `transform`, in shape slot order, until it returns `false`.
    /// Errors: an invalid shape, a non-finite transform or one whose
    /// rotation is not unit length ([`QueryProblem::NotUnitRotation`](crate::QueryProblem::NotUnitRotation);
    /// within [`UNIT_ROTATION_TOLERANCE`](janus2d_core::limits::UNIT_ROTATION_TOLERANCE)
    /// it is normalised).
    pub fn overlap_shape<F: FnMut(crate::query::ShapeOverlap) -> bool>(
        &self,
        shape: &Shape,
        transform: &Transform,
        filter: &crate::query::QueryFilter,
        callback: F,
    ) -> Result<(), WorldError> {
        let ctx = self.query_context(filter);
        crate::query::overlap_shape(&ctx, shape, transform, filter, callback)
    }

    /// Hands `callback` every solid shape that contains `point` (segments
    /// and chain segments never do), in shape slot order, until it returns
    /// `false`: what is under the mouse. Errors: a non-finite point.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::new(1.0, 1.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// let mut picked = None;
    /// world.overlap_point(Vec2::new(1.2, 0.7), &QueryFilter::default(), |o| {
    ///     picked = Some(o.body);
    ///     false // the first is enough
    /// }).unwrap();
    /// assert_eq!(picked, Some(b));
    /// ```
    pub fn overlap_point<F: FnMut(crate::query::ShapeOverlap) -> bool>(
        &self,
        point: Vec2,
        filter: &crate::query::QueryFilter,
        callback: F,
    ) -> Result<(), WorldError> {
        let ctx = self.query_context(filter);
        crate::query::overlap_point(&ctx, point, filter, callback)
    }

    /// Distance between the surfaces of two shapes at their bodies' current
    /// poses, their closest points and the unit normal from `a` to `b`
    /// (distance 0 when they touch or overlap). Errors: a stale or foreign
    /// shape handle.
    pub fn shape_distance(
        &self,
        a: ShapeHandle,
        b: ShapeHandle,
    ) -> Result<janus2d_core::geometry::DistanceOutput, WorldError> {
        let owner = self.bodies.owner();
        let sa = self.collision.shapes.slot(a, owner)?;
        let sb = self.collision.shapes.slot(b, owner)?;
        let ctx = self.query_context(&crate::query::QueryFilter::default());
        Ok(crate::query::distance_between(&ctx, sa, sb))
    }

    /// The point of the shapes' surfaces nearest to `point` within
    /// `max_distance` m (`Real::INFINITY`: anywhere), with its shape, body,
    /// outward normal and distance, or `None` when no shape the filter
    /// accepts is that close. A shape that holds the point
    /// ([`PointProjection::inside`](crate::query::PointProjection::inside);
    /// the point is then `distance` under its surface) is nearer than any
    /// other, the deepest first; ties go to the lower shape slot. As Rapier's
    /// `project_point` with `solid = false`, Box2D has no such query.
    ///
    /// Point queries see each shape where it is, crossing copies included
    /// (as [`overlap_point`](Self::overlap_point)); `through_portals` does
    /// not apply to them.
    ///
    /// Errors: a non-finite point, a NaN or negative `max_distance`
    /// ([`WorldError::BadQuery`]; the world is unchanged).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::fixed(Vec2::new(3.0, 0.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(1.0, 1.0)).unwrap();
    /// let p = world
    ///     .project_point(Vec2::new(0.0, 0.5), 10.0, &QueryFilter::default())
    ///     .unwrap()
    ///     .unwrap();
    /// // The left face of the box is at x = 2.
    /// assert!((p.point - Vec2::new(2.0, 0.5)).length() < 1e-5);
    /// assert!((p.distance - 2.0).abs() < 1e-5 && !p.inside);
    /// assert!((p.normal - Vec2::new(-1.0, 0.0)).length() < 1e-5);
    /// ```
    pub fn project_point(
        &self,
        point: Vec2,
        max_distance: Real,
        filter: &crate::query::QueryFilter,
    ) -> Result<Option<crate::query::PointProjection>, WorldError> {
        let ctx = self.query_context(filter);
        crate::query::project_point(&ctx, point, max_distance, filter)
    }

    /// The point of one shape's surface nearest to `point` (as
    /// [`project_point`](Self::project_point), on that shape alone, whatever
    /// its filter or sensor flag).
    ///
    /// Errors: a stale or foreign shape handle, a non-finite point.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Circle;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let s = world.create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, 2.0).unwrap()).unwrap();
    /// let p = world.shape_project_point(s, Vec2::new(0.5, 0.0)).unwrap();
    /// assert!(p.inside && (p.distance - 1.5).abs() < 1e-6);
    /// assert!((p.point - Vec2::new(2.0, 0.0)).length() < 1e-6);
    /// ```
    pub fn shape_project_point(
        &self,
        shape: ShapeHandle,
        point: Vec2,
    ) -> Result<crate::query::PointProjection, WorldError> {
        let slot = self.collision.shapes.slot(shape, self.bodies.owner())?;
        let ctx = self.query_context(&crate::query::QueryFilter::default());
        crate::query::project_on_shape(&ctx, slot, point)
    }

    /// The first hit of the ray `origin + s · translation`, `s ∈ [0, 1]`, on
    /// `shape` alone: [`cast_ray_closest`](Self::cast_ray_closest) restricted
    /// to one shape (as Box2D's `b2Shape_RayCast`). `filter` applies as
    /// there: a shape it does not accept (a sensor, another category, the
    /// excluded body, the predicate's `false`) is never hit, and with
    /// `through_portals` the ray goes on through apertures and may hit the
    /// shape beyond them (`portal_hops` says how many). A ray that starts
    /// inside the shape does not hit it.
    ///
    /// Errors: a stale or foreign shape handle, a non-finite origin or
    /// translation, a zero translation.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let near = world.create_body(&BodyDef::fixed(Vec2::new(2.0, 0.0))).unwrap();
    /// world.create_shape(near, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// let far = world.create_body(&BodyDef::fixed(Vec2::new(5.0, 0.0))).unwrap();
    /// let s = world.create_shape(far, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// // The nearer box does not hide the one asked about.
    /// let hit = world
    ///     .shape_ray_cast(s, Vec2::ZERO, Vec2::new(10.0, 0.0), &QueryFilter::default())
    ///     .unwrap()
    ///     .unwrap();
    /// assert!((hit.point.x - 4.5).abs() < 1e-5 && (hit.fraction - 0.45).abs() < 1e-6);
    /// ```
    pub fn shape_ray_cast(
        &self,
        shape: ShapeHandle,
        origin: Vec2,
        translation: Vec2,
        filter: &crate::query::QueryFilter,
    ) -> Result<Option<crate::query::RayHit>, WorldError> {
        let slot = self.collision.shapes.slot(shape, self.bodies.owner())?;
        let ctx = self.query_context(filter);
        crate::query::shape_ray_cast(&ctx, slot, origin, translation, filter)
    }

    /// True when the solid `shape` holds `point` (its surface included;
    /// segments and chain segments never do): the exact test of
    /// [`overlap_point`](Self::overlap_point) on one shape, whatever its
    /// filter or sensor flag (as Box2D's `b2Shape_TestPoint`).
    ///
    /// Errors: a stale or foreign shape handle, a non-finite point.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::fixed(Vec2::new(1.0, 0.0))).unwrap();
    /// let s = world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// assert!(world.shape_test_point(s, Vec2::new(1.4, 0.4)).unwrap());
    /// assert!(!world.shape_test_point(s, Vec2::new(1.6, 0.0)).unwrap());
    /// ```
    pub fn shape_test_point(&self, shape: ShapeHandle, point: Vec2) -> Result<bool, WorldError> {
        let slot = self.collision.shapes.slot(shape, self.bodies.owner())?;
        let ctx = self.query_context(&crate::query::QueryFilter::default());
        crate::query::shape_test_point(&ctx, slot, point)
    }

    /// The shapes overlapping `shape` through sensor contacts now, sorted
    /// by handle: for a sensor, the shapes inside it (its visitors); for any
    /// other shape, the sensors it is inside. This is the set the sensor
    /// events describe: after each step it equals the set before it, plus
    /// the step's `sensor_begin` pairs naming `shape`, minus its
    /// `sensor_end` pairs (see [`CollisionEvents`]).
    /// A crossing copy is a shape of its own, with its own overlaps.
    ///
    /// Errors: a stale or foreign shape handle.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::{Circle, Polygon};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let zone = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let sensor = world
    ///     .create_shape(zone, &ShapeDef::default().sensor(), Polygon::make_box(2.0, 2.0))
    ///     .unwrap();
    /// let ball = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
    /// let s = world.create_shape(ball, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.25).unwrap()).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// assert_eq!(world.sensor_overlaps(sensor).unwrap(), vec![s]);
    /// assert_eq!(world.sensor_overlaps(s).unwrap(), vec![sensor]);
    /// ```
    pub fn sensor_overlaps(&self, shape: ShapeHandle) -> Result<Vec<ShapeHandle>, WorldError> {
        let body = self.shape(shape)?.body;
        let contacts = &self.collision.contacts;
        let mut out: Vec<ShapeHandle> = contacts
            .of_body(body)
            .iter()
            .filter_map(|&id| contacts.get(id))
            .filter(|c| c.sensor && c.touching && c.shapes.contains(&shape))
            .map(|c| {
                if c.shapes[0] == shape {
                    c.shapes[1]
                } else {
                    c.shapes[0]
                }
            })
            .collect();
        out.sort();
        out.dedup();
        Ok(out)
    }
}
