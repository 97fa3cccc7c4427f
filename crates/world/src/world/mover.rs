//! The character mover's world calls: sweep a capsule against the world
//! and gather its collision planes (the plane solving is `crate::mover`'s).

use super::*;

use janus2d_core::geometry::{
    Aabb, CAST_TOLERANCE, Capsule, LINEAR_SLOP, ShapeProxy, shape_cast, shape_distance,
};

use crate::mover::{MoverCast, PlaneResult};
use crate::query::{QueryFilter, QueryProblem, RayHit};

fn bad(field: &'static str, problem: QueryProblem) -> WorldError {
    WorldError::BadQuery { field, problem }
}

fn check_mover(mover: &Capsule) -> Result<(), WorldError> {
    Shape::Capsule(*mover)
        .validate()
        .map_err(|e| bad("mover", QueryProblem::Shape(e)))
}

/// Gap between the surfaces of `a` (placed by `xf_a`) and the mover, with the
/// unit normal from `a` to the mover and the closest point on `a`'s surface;
/// the gap is negative when they overlap (down to minus both radii when the
/// cores meet, where the normal is zero).
fn separation(a: &ShapeProxy, xf_a: &Transform, mover: &ShapeProxy) -> (Real, Vec2, Vec2) {
    let mut core_a = *a;
    core_a.radius = 0.0;
    let mut core_m = *mover;
    core_m.radius = 0.0;
    let out = shape_distance(&core_a, xf_a, &core_m, &Transform::IDENTITY);
    let gap = out.distance - a.radius - mover.radius;
    (gap, out.normal, out.point_a + a.radius * out.normal)
}

impl World {
    /// The shape slots a mover query looks at: the broadphase's candidates
    /// in `aabb`, in slot order, that `filter` accepts, without a chain
    /// segment the mover's centre `centre` is behind (one-sided).
    fn mover_candidates(&self, aabb: &Aabb, centre: Vec2, filter: &QueryFilter) -> Vec<u32> {
        let shapes = &self.collision.shapes;
        let mut slots = Vec::new();
        self.collision.broadphase.query(aabb, |_, slot| {
            slots.push(slot);
            true
        });
        slots.sort_unstable();
        slots.dedup();
        slots.retain(|&slot| {
            let data = shapes.at(slot);
            if !filter.accepts_shape(shapes.handle_of(slot, self.bodies.owner()), data) {
                return false;
            }
            if let Shape::ChainSegment(c) = &data.geometry {
                let xf = self.mover_transform_of(data.body);
                let p1 = xf.apply(c.segment.point1);
                return (centre - p1).dot(xf.q.rotate(c.normal())) >= 0.0;
            }
            true
        });
        slots
    }

    fn mover_transform_of(&self, body: BodyHandle) -> Transform {
        self.bodies
            .sim(body)
            .map_or(Transform::IDENTITY, |s| s.transform)
    }

    /// Sweeps the capsule `mover` (world coordinates) along `translation`
    /// and returns how far it gets: the fraction of `translation` before it
    /// meets a solid shape `filter` accepts (static, kinematic or dynamic),
    /// and that shape (as Box2D 3.2's `b2World_CastMover`).
    ///
    /// A shape the mover already touches or overlaps at the start does not
    /// stop it at once: it stops the mover only where the mover would go
    /// [`LINEAR_SLOP`] deeper into it than it already is (Box2D's
    /// "encroach"), so a mover resting on the floor slides along it, and one
    /// whose cores already cross a shape's ignores that shape (push it out
    /// with [`collide_mover`](Self::collide_mover) and
    /// [`solve_planes`](crate::mover::solve_planes)). The sweep is exact
    /// whatever the speed: nothing is tunnelled. A zero translation is
    /// fraction 1, no hit. Chain segments stop the mover only from their
    /// front.
    ///
    /// **Portals**: the mover does not go through portals
    /// (`filter.through_portals` is ignored): the wall that carries a portal
    /// is a wall to it. Crossing is the caller's for now (move the
    /// character with the pair's portal map, see [`crate::portal`]).
    ///
    /// Errors: an invalid capsule (non-positive radius, non-finite,
    /// degenerate core: `BadQuery { field: "mover" }`), a non-finite
    /// translation (`BadQuery { field: "translation" }`).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::{Capsule, Polygon};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let wall = world.create_body(&BodyDef::fixed(Vec2::new(5.0, 0.0))).unwrap();
    /// world.create_shape(wall, &ShapeDef::default(), Polygon::make_box(0.025, 2.0)).unwrap();
    /// let mover = Capsule::new(Vec2::new(0.0, -0.25), Vec2::new(0.0, 0.25), 0.25).unwrap();
    /// // 20 m in one go: stopped at the wall's face (x = 4.975), less the radius.
    /// let cast = world.cast_mover(&mover, Vec2::new(20.0, 0.0), &QueryFilter::default()).unwrap();
    /// let x = cast.fraction * 20.0;
    /// assert!(x > 4.7 && x <= 4.725, "{x}");
    /// assert_eq!(cast.hit.unwrap().body, wall);
    /// ```
    pub fn cast_mover(
        &self,
        mover: &Capsule,
        translation: Vec2,
        filter: &QueryFilter,
    ) -> Result<MoverCast, WorldError> {
        self.cast_mover_with(mover, translation, filter, |_| true)
    }

    /// [`cast_mover`](Self::cast_mover) where `accept` decides, hit by hit
    /// (nearest first, ties by shape slot), whether a shape stops the mover:
    /// the first hit it accepts is the result. A one-way platform is a shape
    /// whose hits are accepted only when their normal points up. Errors as
    /// [`cast_mover`](Self::cast_mover).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::{Capsule, Polygon};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let ledge = world.create_body(&BodyDef::fixed(Vec2::new(0.0, 2.0))).unwrap();
    /// world.create_shape(ledge, &ShapeDef::default(), Polygon::make_box(1.0, 0.1)).unwrap();
    /// let mover = Capsule::new(Vec2::new(0.0, -0.25), Vec2::new(0.0, 0.25), 0.25).unwrap();
    /// let one_way = |hit: &janus2d_world::RayHit| hit.normal.y > 0.5;
    /// // Jumping up through the ledge: its underside (normal down) lets it by.
    /// let up = world.cast_mover_with(&mover, Vec2::new(0.0, 3.0), &QueryFilter::default(), one_way).unwrap();
    /// assert_eq!(up.fraction, 1.0);
    /// ```
    pub fn cast_mover_with<F: FnMut(&RayHit) -> bool>(
        &self,
        mover: &Capsule,
        translation: Vec2,
        filter: &QueryFilter,
        mut accept: F,
    ) -> Result<MoverCast, WorldError> {
        check_mover(mover)?;
        if !vec_is_finite(translation) {
            return Err(bad("translation", QueryProblem::NonFinite));
        }
        let miss = MoverCast {
            fraction: 1.0,
            hit: None,
        };
        if translation.length_squared() == 0.0 {
            return Ok(miss);
        }
        let shape = Shape::Capsule(*mover);
        let end = Transform {
            p: translation,
            q: Rot::IDENTITY,
        };
        let swept = shape
            .compute_aabb(&Transform::IDENTITY)
            .union(&shape.compute_aabb(&end));
        let centre = 0.5 * (mover.center1 + mover.center2);
        let proxy_m = ShapeProxy::from_shape(&shape);
        let owner = self.bodies.owner();
        let mut hits: Vec<(Real, u32, RayHit)> = Vec::new();
        for slot in self.mover_candidates(&swept, centre, filter) {
            let data = self.collision.shapes.at(slot);
            let xf = self.mover_transform_of(data.body);
            let proxy_a = ShapeProxy::from_shape(&data.geometry);
            let (gap, _, _) = separation(&proxy_a, &xf, &proxy_m);
            let mut caster = proxy_m;
            if gap < CAST_TOLERANCE {
                // Touching or overlapping: may go LINEAR_SLOP deeper.
                caster.radius -= (-gap).max(0.0) + LINEAR_SLOP;
                if caster.radius <= 0.0 {
                    continue;
                }
            }
            if let Some(h) = shape_cast(
                &proxy_a,
                &xf,
                &caster,
                &Transform::IDENTITY,
                translation,
                1.0,
            ) {
                hits.push((
                    h.fraction,
                    slot,
                    RayHit {
                        shape: self.collision.shapes.handle_of(slot, owner),
                        body: data.body,
                        point: h.point,
                        normal: h.normal,
                        fraction: h.fraction,
                        portal_hops: 0,
                        last_portal: None,
                    },
                ));
            }
        }
        hits.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for (fraction, _, hit) in &hits {
            if accept(hit) {
                return Ok(MoverCast {
                    fraction: fraction.clamp(0.0, 1.0),
                    hit: Some(*hit),
                });
            }
        }
        Ok(miss)
    }

    /// Hands `callback` a [`PlaneResult`] for every solid shape `filter`
    /// accepts whose surface is within `margin` (m, ≥ 0; 0: touching or
    /// overlapping only) of the capsule `mover` (world coordinates), in shape
    /// slot order, until it returns `false` (as Box2D 3.2's
    /// `b2World_CollideMover`). The normal is the obstacle's, towards the
    /// mover; when the mover's core crosses the shape's it is the direction
    /// from the shape's centre to the mover's. Chain segments count only
    /// from their front; portals as [`cast_mover`](Self::cast_mover).
    ///
    /// Errors: an invalid capsule (`BadQuery { field: "mover" }`), a
    /// negative or non-finite margin (`OutOfRange("margin")`).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::{Capsule, Polygon};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0))).unwrap();
    /// world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(10.0, 1.0)).unwrap();
    /// // The capsule's bottom is 1 cm into the ground (top face at y = 0).
    /// let mover = Capsule::new(Vec2::new(0.0, 0.24), Vec2::new(0.0, 0.74), 0.25).unwrap();
    /// let mut planes = Vec::new();
    /// world.collide_mover(&mover, 0.0, &QueryFilter::default(), |p| { planes.push(*p); true }).unwrap();
    /// assert_eq!(planes.len(), 1);
    /// assert!((planes[0].separation + 0.01).abs() < 1e-4);
    /// assert!((planes[0].normal - Vec2::Y).length() < 1e-4);
    /// ```
    pub fn collide_mover<F: FnMut(&PlaneResult) -> bool>(
        &self,
        mover: &Capsule,
        margin: Real,
        filter: &QueryFilter,
        mut callback: F,
    ) -> Result<(), WorldError> {
        check_mover(mover)?;
        if !margin.is_finite() || margin < 0.0 {
            return Err(WorldError::OutOfRange("margin"));
        }
        let shape = Shape::Capsule(*mover);
        let aabb = shape.compute_aabb(&Transform::IDENTITY).fattened(margin);
        let centre = 0.5 * (mover.center1 + mover.center2);
        let proxy_m = ShapeProxy::from_shape(&shape);
        let owner = self.bodies.owner();
        for slot in self.mover_candidates(&aabb, centre, filter) {
            let data = self.collision.shapes.at(slot);
            let xf = self.mover_transform_of(data.body);
            let proxy_a = ShapeProxy::from_shape(&data.geometry);
            let (gap, mut normal, mut point) = separation(&proxy_a, &xf, &proxy_m);
            if gap > margin {
                continue;
            }
            if normal == Vec2::ZERO {
                // The cores cross: out along the line between the centres.
                let c = xf.apply(data.geometry.centroid());
                normal = (centre - c).normalize_or(Vec2::Y);
                point = c;
            }
            let result = PlaneResult {
                shape: self.collision.shapes.handle_of(slot, owner),
                body: data.body,
                normal,
                separation: gap,
                point,
            };
            if !callback(&result) {
                break;
            }
        }
        Ok(())
    }

    /// Velocity of the point `point` (world, m) of `body`, m/s:
    /// `v + ω × (point − centre of mass)` (0 for a static body), what a
    /// moving platform gives a rider.
    pub(crate) fn mover_point_velocity(
        &self,
        body: BodyHandle,
        point: Vec2,
    ) -> Result<Vec2, WorldError> {
        if !vec_is_finite(point) {
            return Err(WorldError::NonFinite("point"));
        }
        let v = self.linear_velocity(body)?;
        let w = self.angular_velocity(body)?;
        let c = self.center_of_mass(body)?;
        Ok(v + janus2d_core::math::cross_sv(w, point - c))
    }
}
