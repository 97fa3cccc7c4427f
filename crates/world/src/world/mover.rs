//! The character mover's world calls: sweep a capsule against the world
//! and gather its collision planes (the plane solving is `crate::mover`'s).

use super::*;

use janus2d_core::geometry::{
    Aabb, CAST_TOLERANCE, Capsule, LINEAR_SLOP, ShapeProxy, shape_cast, shape_distance,
};

use janus2d_core::geometry::CastHit;

use crate::mover::{MOVER_PLANE_TOLERANCE, MoverCast, MoverCrossing, PlaneResult};
use crate::query::{PortalHop, QueryAperture, QueryFilter, QueryProblem, RayHit};
use janus2d_constraints::portal_map::PortalFrame;

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

/// Frame coordinates `(s, t)` of `p` in an aperture's frame: `s` along the
/// outward normal (positive in front), `t` along the aperture.
fn aperture_coords(a: &QueryAperture, p: Vec2) -> (Real, Real) {
    let f = &a.map.frame1;
    let d = p - f.point;
    (d.dot(f.normal), cross(f.normal, d))
}

/// True when `p` lies in the hole of the aperture in its wall: within its
/// span, from just in front of the surface to `2w` behind it (as the
/// narrowphase's and the queries' holes).
fn in_hole(a: &QueryAperture, p: Vec2) -> bool {
    let (s, t) = aperture_coords(a, p);
    t.abs() < a.half_width && s > -2.0 * a.half_width && s <= 2.0 * LINEAR_SLOP
}

/// True when `p` lies behind the aperture's plane within its span, down to
/// `2w` (where the part of a mover that went in is on the other side).
fn behind(a: &QueryAperture, p: Vec2) -> bool {
    let (s, t) = aperture_coords(a, p);
    t.abs() < a.half_width && s > -2.0 * a.half_width && s < 0.0
}

/// True when the capsule goes into the aperture: its centre in front of the
/// plane (within [`MOVER_PLANE_TOLERANCE`]) and within the span, and part
/// of it behind the plane.
fn passes(a: &QueryAperture, mover: &Capsule) -> bool {
    let (s, t) = aperture_coords(a, 0.5 * (mover.center1 + mover.center2));
    let (s1, _) = aperture_coords(a, mover.center1);
    let (s2, _) = aperture_coords(a, mover.center2);
    s >= -MOVER_PLANE_TOLERANCE && t.abs() < a.half_width && s1.min(s2) - mover.radius < 0.0
}

/// The capsule moved by `d`.
fn moved(mover: &Capsule, d: Vec2) -> Capsule {
    Capsule {
        center1: mover.center1 + d,
        center2: mover.center2 + d,
        radius: mover.radius,
    }
}

/// The capsule's image through the aperture: its core mapped by `T`, its
/// radius scaled by `η`.
fn image(a: &QueryAperture, mover: &Capsule) -> Capsule {
    Capsule {
        center1: a.map.map_point(mover.center1),
        center2: a.map.map_point(mover.center2),
        radius: a.map.eta * mover.radius,
    }
}

/// The two end points of the aperture (its lips).
fn lips(a: &QueryAperture) -> [Vec2; 2] {
    let f = &a.map.frame1;
    [
        f.point - a.half_width * f.tangent,
        f.point + a.half_width * f.tangent,
    ]
}

/// The first hit of the mover (proxy `m`) swept along `translation` against
/// `a` placed by `xf_a`, a shape the mover already touches or overlaps
/// stopping it only [`LINEAR_SLOP`] deeper (none when the cores cross).
fn sweep_one(
    a: &ShapeProxy,
    xf_a: &Transform,
    m: &ShapeProxy,
    translation: Vec2,
) -> Option<CastHit> {
    let (gap, _, _) = separation(a, xf_a, m);
    let mut caster = *m;
    if gap < CAST_TOLERANCE {
        // Touching or overlapping: may go LINEAR_SLOP deeper.
        caster.radius -= (-gap).max(0.0) + LINEAR_SLOP;
        if caster.radius <= 0.0 {
            return None;
        }
    }
    shape_cast(a, xf_a, &caster, &Transform::IDENTITY, translation, 1.0)
}

/// Distance from `p` to the segment `a`–`b`, and the segment's closest point.
fn closest_on_segment(a: Vec2, b: Vec2, p: Vec2) -> (Real, Vec2) {
    let ab = b - a;
    let len2 = ab.length_squared();
    let u = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let c = a + u * ab;
    ((p - c).length(), c)
}

/// Whether what the mover's image meets at `point` (on `body`) on the far
/// side counts: in front of the partner portal's plane (not behind it, up
/// to [`MOVER_PLANE_TOLERANCE`]), not on the partner's wall at its surface
/// (the near side's lips stand for it), not in a hole, not a portal wall
/// the image's core crosses.
fn far_side_keeps(
    apertures: &[QueryAperture],
    partner: Option<&QueryAperture>,
    body: BodyHandle,
    point: Vec2,
    cores_cross: bool,
) -> bool {
    if let Some(b) = partner {
        let (s, _) = aperture_coords(b, point);
        if s < -MOVER_PLANE_TOLERANCE || (b.body == body && s <= MOVER_PLANE_TOLERANCE) {
            return false;
        }
    }
    !apertures
        .iter()
        .any(|b| b.body == body && (in_hole(b, point) || cores_cross))
}

/// The capsule's cross-section with the line of the frame's plane: its two
/// ends (`None` when the capsule does not reach the plane). The core is
/// sampled at 33 points (the ends' error is second order in the spacing).
fn cross_section(mover: &Capsule, f: &PortalFrame) -> Option<(Vec2, Vec2)> {
    const SAMPLES: usize = 32;
    let (mut lo, mut hi) = (Real::INFINITY, Real::NEG_INFINITY);
    for i in 0..=SAMPLES {
        let u = i as Real / SAMPLES as Real;
        let c = mover.center1 + u * (mover.center2 - mover.center1);
        let d = c - f.point;
        let (s, t) = (d.dot(f.normal), d.dot(f.tangent));
        let h2 = mover.radius * mover.radius - s * s;
        if h2 >= 0.0 {
            let h = h2.sqrt();
            lo = lo.min(t - h);
            hi = hi.max(t + h);
        }
    }
    (lo <= hi).then(|| (f.point + lo * f.tangent, f.point + hi * f.tangent))
}

/// A plane the mover query found: the slot, the plane, and whether the
/// cores crossed (the normal then the fallback between the centres).
struct Found {
    slot: u32,
    gap: Real,
    normal: Vec2,
    point: Vec2,
    cores_cross: bool,
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
    /// **Portals** (`filter.through_portals`; off: a portal's wall is a wall
    /// like any other): a wall that carries a portal does not stop the
    /// mover inside the aperture's hole (its span, from the surface to `2w`
    /// behind it, as the queries' and the narrowphase's holes), and the
    /// aperture's two end points (its lips) do. While the mover goes into
    /// an aperture (its centre in front of the plane within the span, part
    /// of it behind), what lies behind that plane within the span does not
    /// stop it, and its image on the far side (core mapped by `T`, radius
    /// × `η`, swept along `η Q · translation`) is stopped by what lies in
    /// front of the partner portal: such a hit has `portal_hops` 1 and its
    /// point and normal mapped back. The cast does not follow the mover
    /// through: [`mover_crossing`](Self::mover_crossing) says where its
    /// centre reaches an aperture, and the
    /// [`CharacterController`](crate::character::CharacterController)
    /// takes it through there.
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
        let owner = self.bodies.owner();
        let shapes = &self.collision.shapes;
        let apertures = self.mover_apertures(filter);
        let end = moved(mover, translation);
        let going: Vec<bool> = apertures
            .iter()
            .map(|a| passes(a, mover) || passes(a, &end))
            .collect();
        let as_hit = |slot: u32, h: &CastHit, hop: Option<PortalHop>| RayHit {
            shape: shapes.handle_of(slot, owner),
            body: shapes.at(slot).body,
            point: h.point,
            normal: h.normal,
            fraction: h.fraction,
            portal_hops: u32::from(hop.is_some()),
            last_portal: hop,
        };
        let mut hits: Vec<(Real, u32, RayHit)> = Vec::new();
        for (fraction, slot, h) in self.mover_sweep(mover, translation, filter) {
            let body = shapes.at(slot).body;
            if !Self::mover_drops(&apertures, &going, body, h.point, false) {
                hits.push((fraction, slot, as_hit(slot, &h, None)));
            }
        }
        if !apertures.is_empty() {
            let proxy_m = ShapeProxy::from_shape(&Shape::Capsule(*mover));
            for (a, &go) in apertures.iter().zip(&going) {
                // The lips: the wall's surface ends there.
                for corner in lips(a) {
                    let lip = ShapeProxy::point(corner);
                    if let Some(h) = sweep_one(&lip, &Transform::IDENTITY, &proxy_m, translation)
                        && let Some(slot) = self.mover_lip_shape(a.body, corner, filter)
                    {
                        hits.push((h.fraction, slot, as_hit(slot, &h, None)));
                    }
                }
                if !go {
                    continue;
                }
                // The far side: what the part that went in meets there.
                let back = a.map.inverse();
                let partner = apertures
                    .iter()
                    .find(|b| b.pair == a.pair && b.side != a.side);
                let hop = PortalHop {
                    pair: a.pair,
                    entered: a.side,
                    entry_point: a.map.frame1.point,
                    exit_point: a.map.frame2.point,
                };
                let far = image(a, mover);
                for (fraction, slot, h) in
                    self.mover_sweep(&far, a.map.map_vector(translation), filter)
                {
                    let body = shapes.at(slot).body;
                    if !far_side_keeps(&apertures, partner, body, h.point, false) {
                        continue;
                    }
                    let seen = CastHit {
                        point: back.map_point(h.point),
                        normal: back.map_direction(h.normal),
                        fraction,
                    };
                    hits.push((fraction, slot, as_hit(slot, &seen, Some(hop))));
                }
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
    /// from their front.
    ///
    /// **Portals** (`filter.through_portals`), as
    /// [`cast_mover`](Self::cast_mover): nothing inside an aperture's hole,
    /// nor a wall the mover's core crosses while it goes into that wall's
    /// aperture; the lips as points (with the wall's shape, after the
    /// shapes); then, while the mover goes into an aperture, what its image
    /// touches in front of the partner portal, mapped back (normal by
    /// `Qᵀ`, point by `T⁻¹`, separation ÷ `η`).
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
        let owner = self.bodies.owner();
        let shapes = &self.collision.shapes;
        let apertures = self.mover_apertures(filter);
        let going: Vec<bool> = apertures.iter().map(|a| passes(a, mover)).collect();
        let mut out: Vec<PlaneResult> = Vec::new();
        for f in self.mover_touches(mover, margin, filter, None) {
            let body = shapes.at(f.slot).body;
            if Self::mover_drops(&apertures, &going, body, f.point, f.cores_cross) {
                continue;
            }
            out.push(PlaneResult {
                shape: shapes.handle_of(f.slot, owner),
                body,
                normal: f.normal,
                separation: f.gap,
                point: f.point,
            });
        }
        let near = out.len();
        for (a, &go) in apertures.iter().zip(&going) {
            // The lips, unless the wall's own plane is already there.
            for corner in lips(a) {
                let (d, closest) = closest_on_segment(mover.center1, mover.center2, corner);
                let gap = d - mover.radius;
                if gap > margin || d <= 0.0 {
                    continue;
                }
                let Some(slot) = self.mover_lip_shape(a.body, corner, filter) else {
                    continue;
                };
                let shape = shapes.handle_of(slot, owner);
                if out[..near]
                    .iter()
                    .any(|r| r.shape == shape && (r.point - corner).length() <= LINEAR_SLOP)
                {
                    continue;
                }
                out.push(PlaneResult {
                    shape,
                    body: a.body,
                    normal: (closest - corner) / d,
                    separation: gap,
                    point: corner,
                });
            }
            if !go {
                continue;
            }
            // The far side, seen back through the aperture.
            let back = a.map.inverse();
            let partner = apertures
                .iter()
                .find(|b| b.pair == a.pair && b.side != a.side);
            let far = image(a, mover);
            let front = partner.map(|b| &b.map.frame1);
            for f in self.mover_touches(&far, a.map.eta * margin, filter, front) {
                let body = shapes.at(f.slot).body;
                if !far_side_keeps(&apertures, partner, body, f.point, f.cores_cross) {
                    continue;
                }
                out.push(PlaneResult {
                    shape: shapes.handle_of(f.slot, owner),
                    body,
                    normal: back.map_direction(f.normal),
                    separation: f.gap / a.map.eta,
                    point: back.map_point(f.point),
                });
            }
        }
        for r in &out {
            if !callback(r) {
                break;
            }
        }
        Ok(())
    }

    /// The portal apertures a mover query with `filter` sees (none unless
    /// `filter.through_portals`).
    fn mover_apertures(&self, filter: &QueryFilter) -> Vec<QueryAperture> {
        if filter.through_portals {
            self.portals
                .query_apertures(&self.bodies, self.bodies.owner())
        } else {
            Vec::new()
        }
    }

    /// The accepted shape of `body` whose surface is within
    /// [`LINEAR_SLOP`] of `point` (the nearest; ties by slot): the wall
    /// shape that carries an aperture's lip.
    fn mover_lip_shape(&self, body: BodyHandle, point: Vec2, filter: &QueryFilter) -> Option<u32> {
        let shapes = &self.collision.shapes;
        let probe = ShapeProxy::point(point);
        let xf = self.mover_transform_of(body);
        let mut best: Option<(Real, u32)> = None;
        for &slot in shapes.of_body(body) {
            let data = shapes.at(slot);
            if data.def.is_sensor
                || !filter.accepts_shape(shapes.handle_of(slot, self.bodies.owner()), data)
            {
                continue;
            }
            let d = shape_distance(
                &ShapeProxy::from_shape(&data.geometry),
                &xf,
                &probe,
                &Transform::IDENTITY,
            )
            .distance;
            if d <= LINEAR_SLOP && best.is_none_or(|(b, _)| d < b) {
                best = Some((d, slot));
            }
        }
        best.map(|(_, slot)| slot)
    }

    /// Whether a result of the mover's own side is dropped by the
    /// apertures: on a wall inside its hole; behind an aperture the mover
    /// goes into (`going`); a wall the mover's core crosses while it goes
    /// into one of that wall's apertures.
    fn mover_drops(
        apertures: &[QueryAperture],
        going: &[bool],
        body: BodyHandle,
        point: Vec2,
        cores_cross: bool,
    ) -> bool {
        apertures.iter().zip(going).any(|(a, &go)| {
            (a.body == body && (in_hole(a, point) || (go && cores_cross)))
                || (go && behind(a, point))
        })
    }

    /// Every first hit of the capsule `mover` swept along `translation`
    /// against the candidates `filter` accepts: `(fraction, slot, hit)`.
    fn mover_sweep(
        &self,
        mover: &Capsule,
        translation: Vec2,
        filter: &QueryFilter,
    ) -> Vec<(Real, u32, CastHit)> {
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
        let mut hits = Vec::new();
        for slot in self.mover_candidates(&swept, centre, filter) {
            let data = self.collision.shapes.at(slot);
            let xf = self.mover_transform_of(data.body);
            let proxy_a = ShapeProxy::from_shape(&data.geometry);
            if let Some(h) = sweep_one(&proxy_a, &xf, &proxy_m, translation) {
                hits.push((h.fraction, slot, h));
            }
        }
        hits
    }

    /// Every shape `filter` accepts within `margin` of the capsule
    /// `mover`, in slot order. With `front` (a portal's frame: the mover is
    /// an image there, only its part in front of that plane is real), a
    /// shape nearest to the part behind the plane is measured to the
    /// capsule's cross-section on the plane instead (the nearest point of
    /// a convex part cut by a plane lies on the cut when the whole's does
    /// not lie in the part), and left out when there is none.
    fn mover_touches(
        &self,
        mover: &Capsule,
        margin: Real,
        filter: &QueryFilter,
        front: Option<&PortalFrame>,
    ) -> Vec<Found> {
        let shape = Shape::Capsule(*mover);
        let aabb = shape.compute_aabb(&Transform::IDENTITY).fattened(margin);
        let centre = 0.5 * (mover.center1 + mover.center2);
        let proxy_m = ShapeProxy::from_shape(&shape);
        let mut out = Vec::new();
        for slot in self.mover_candidates(&aabb, centre, filter) {
            let data = self.collision.shapes.at(slot);
            let xf = self.mover_transform_of(data.body);
            let proxy_a = ShapeProxy::from_shape(&data.geometry);
            let (mut gap, mut normal, mut point) = separation(&proxy_a, &xf, &proxy_m);
            if let Some(f) = front
                && normal != Vec2::ZERO
                && (point + gap * normal - f.point).dot(f.normal) < -MOVER_PLANE_TOLERANCE
            {
                let Some((p0, p1)) = cross_section(mover, f) else {
                    continue;
                };
                let chord = ShapeProxy {
                    points: {
                        let mut pts = [Vec2::ZERO; janus2d_core::geometry::MAX_POLYGON_VERTICES];
                        pts[0] = p0;
                        pts[1] = p1;
                        pts
                    },
                    count: 2,
                    radius: 0.0,
                };
                (gap, normal, point) = separation(&proxy_a, &xf, &chord);
            }
            if gap > margin {
                continue;
            }
            let cores_cross = normal == Vec2::ZERO;
            if cores_cross {
                // The cores cross: out along the line between the centres.
                let c = xf.apply(data.geometry.centroid());
                normal = (centre - c).normalize_or(Vec2::Y);
                point = c;
            }
            out.push(Found {
                slot,
                gap,
                normal,
                point,
                cores_cross,
            });
        }
        out
    }

    /// The portal aperture whose plane the centre of the capsule `mover`
    /// (world coordinates) first crosses from the front, within the
    /// aperture's span, as it moves along `translation`: where a
    /// [`CharacterController`](crate::character::CharacterController) goes
    /// through to the partner portal. `None` when it crosses none, or when
    /// `filter.through_portals` is off.
    ///
    /// The crossing's [`map`](MoverCrossing::map) takes the mover to the
    /// far side: points by `T(x) = P₂ + η Q (x − P₁)`, displacements and
    /// velocities relative to the portals by `η Q`, sizes by `η`.
    ///
    /// Errors: an invalid capsule (`BadQuery { field: "mover" }`), a
    /// non-finite translation (`BadQuery { field: "translation" }`).
    ///
    /// ```
    /// use janus2d_world::{PortalDef, PortalPairDef, QueryFilter, ShapeDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::{Capsule, Polygon};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let a = world.create_body(&BodyDef::fixed(Vec2::new(5.5, 0.0))).unwrap();
    /// world.create_shape(a, &ShapeDef::default(), Polygon::make_box(0.5, 3.0)).unwrap();
    /// let b = world.create_body(&BodyDef::fixed(Vec2::new(-20.0, 0.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 3.0)).unwrap();
    /// // Portal a on the face x = 5 (facing -x), portal b twice as wide.
    /// world.create_portal_pair(&PortalPairDef::new(
    ///     PortalDef::new(a, Vec2::new(-0.5, 0.0), -Vec2::X, 1.0),
    ///     PortalDef::new(b, Vec2::new(0.5, 0.0), Vec2::X, 2.0),
    /// )).unwrap();
    /// let mover = Capsule::new(Vec2::new(4.0, -0.25), Vec2::new(4.0, 0.25), 0.25).unwrap();
    /// let through = QueryFilter::default().through_portals();
    /// let c = world.mover_crossing(&mover, Vec2::new(2.0, 0.0), &through).unwrap().unwrap();
    /// assert!((c.fraction - 0.5).abs() < 1e-6 && c.entered == 0 && c.map.eta == 2.0);
    /// assert!((c.map.map_point(c.point) - Vec2::new(-19.5, 0.0)).length() < 1e-5);
    /// // Without through_portals nothing is crossed.
    /// assert!(world.mover_crossing(&mover, Vec2::new(2.0, 0.0), &QueryFilter::default()).unwrap().is_none());
    /// ```
    pub fn mover_crossing(
        &self,
        mover: &Capsule,
        translation: Vec2,
        filter: &QueryFilter,
    ) -> Result<Option<MoverCrossing>, WorldError> {
        check_mover(mover)?;
        if !vec_is_finite(translation) {
            return Err(bad("translation", QueryProblem::NonFinite));
        }
        let apertures = self.mover_apertures(filter);
        let centre = 0.5 * (mover.center1 + mover.center2);
        let mut best: Option<(Real, usize)> = None;
        for (k, a) in apertures.iter().enumerate() {
            let f = &a.map.frame1;
            let dn = translation.dot(f.normal);
            let (s0, _) = aperture_coords(a, centre);
            if dn >= 0.0 || s0 < -MOVER_PLANE_TOLERANCE {
                continue;
            }
            let u = (-s0 / dn).max(0.0);
            if u > 1.0 || best.is_some_and(|(b, _)| u >= b) {
                continue;
            }
            let (_, t) = aperture_coords(a, centre + u * translation);
            if t.abs() < a.half_width {
                best = Some((u, k));
            }
        }
        Ok(best.map(|(u, k)| {
            let a = &apertures[k];
            let exit_body = apertures
                .iter()
                .find(|b| b.pair == a.pair && b.side != a.side)
                .map_or(a.body, |b| b.body);
            MoverCrossing {
                pair: a.pair,
                entered: a.side,
                fraction: u,
                point: centre + u * translation,
                map: a.map,
                bodies: [a.body, exit_body],
            }
        }))
    }

    /// A mover's velocity `v` (m/s) after the crossing `c`: relative to the
    /// entered portal's body, mapped by `η Q`, plus the exit portal body's
    /// velocity where it comes out (`v₂ = v_B(x₂) + η Q (v − v_A(x₁))`, the
    /// spec's clone velocity).
    pub(crate) fn mover_velocity_through(
        &self,
        c: &MoverCrossing,
        v: Vec2,
    ) -> Result<Vec2, WorldError> {
        let va = self.mover_point_velocity(c.bodies[0], c.point)?;
        let vb = self.mover_point_velocity(c.bodies[1], c.exit_point())?;
        Ok(vb + c.map.map_vector(v - va))
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
