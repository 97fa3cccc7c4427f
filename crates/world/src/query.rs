//! Scene queries: rays, shape casts, overlaps and distances against the
//! shapes of a world, through the broadphase trees and exact against the
//! geometry.
//!
//! | query (on [`World`](crate::World)) | finds                                       | exact test |
//! |------------------------------------|---------------------------------------------|------------|
//! | `cast_ray_with`                    | every hit along a ray, nearest first, to a callback that clips, stops or ignores | [`Shape::ray_cast`] |
//! | `cast_ray_closest`                 | the nearest hit                              | [`Shape::ray_cast`] |
//! | `cast_shape_with`, `cast_shape_closest` | a shape swept along a translation: fraction, point, normal | [`shape_cast`] (GJK, conservative advancement) |
//! | `overlap_aabb`                     | shapes whose surface meets a box (not just their fat boxes) | [`shapes_overlap`] |
//! | `overlap_shape`                    | shapes that touch or overlap a shape          | [`shapes_overlap`] |
//! | `overlap_point`                    | solid shapes that contain a point (picking)   | [`shapes_overlap`] |
//! | `shape_distance`                   | distance and closest points of two shapes     | [`shape_distance`](janus2d_core::geometry::shape_distance) |
//! | `project_point`                    | the nearest surface point of any shape (inside first), [`PointProjection`] | per shape kind, exact |
//! | `shape_project_point`, `shape_ray_cast`, `shape_test_point` | the same queries on one named shape | as above |
//! | `sensor_overlaps`                  | the shapes a sensor holds (or the sensors a shape is in), as its events say | the contacts |
//!
//! **Rules shared by every query.**
//! - A shape is tested when [`QueryFilter::accepts_shape`] it: category/mask as
//!   Box2D (`shape.category & query.mask != 0` and `shape.mask &
//!   query.category != 0`), not on the excluded body, not a sensor, and
//!   then the filter's [`predicate`](QueryFilter::predicate) closure, if
//!   any, returns `true` for it.
//! - Candidates come from both broadphase trees (fat boxes), then the exact
//!   test decides: a fat box that the query meets is not a hit.
//! - Order is deterministic: cast hits are delivered by increasing fraction
//!   (ties by shape slot), overlaps by shape slot, whatever the tree's shape.
//! - A non-finite or degenerate input is [`WorldError::BadQuery`] naming the
//!   field; the world is never changed by a query.
//! - A ray that starts inside a solid shape does not hit it (as Box2D).
//!
//! **Cast callbacks** ([`RayHit`] → `Real`, as Box2D's `b2CastResultFcn`):
//! return `-1` to ignore the hit, `0` to stop, the hit's fraction to clip the
//! ray there (what a closest-hit query does), or `1` to go on unclipped.
//!
//! **Line of sight through portals** ([`QueryFilter::through_portals`], off
//! by default): a ray (or the reference point of a cast shape) that crosses a
//! portal aperture from its front continues from the mapped point `T(x)` in
//! the mapped direction, its remaining length scaled by `η` (a cast shape is
//! also turned by `Q` and scaled by `η`). The wall that carries the aperture
//! is not hit inside the aperture (the hole of the portal clipping); a cast
//! shape too wide for the aperture meets its lips (the aperture's end
//! points). Each hit
//! reports how many apertures it went through ([`RayHit::portal_hops`]) and
//! the last one ([`RayHit::last_portal`]); fractions stay those of the
//! original translation. At most [`MAX_PORTAL_HOPS`] apertures are crossed;
//! after that the apertures are walls again (two facing portals end).
//! Point queries (`overlap_point`, `project_point`, `shape_test_point`)
//! and overlaps see each shape where it is, crossing copies included:
//! `through_portals` applies to rays and casts (`shape_ray_cast` included).

use janus2d_constraints::portal_map::PortalMap;
use janus2d_core::body::{BodyHandle, BodySet};
use janus2d_core::geometry::{
    Aabb, CastHit, DistanceOutput, LINEAR_SLOP, RayInput, Shape, ShapeProxy, shape_cast,
    shapes_overlap,
};
use janus2d_core::handle::{Handle, PortalPairTag};
use janus2d_core::math::{Real, Rot, Transform, Vec2, cross, vec_is_finite};

use crate::broadphase::BroadPhase;
use crate::error::WorldError;
use crate::shapes::{ShapeData, ShapeHandle, ShapeStore};

/// Most portal apertures one ray or shape cast goes through (a count; usual 4).
pub const MAX_PORTAL_HOPS: u32 = 4;

/// A caller's test of each shape a query would otherwise see: `true`
/// keeps it (see [`QueryFilter::with_predicate`]).
///
/// ```
/// use janus2d_world::{QueryFilter, ShapeDef, ShapeHandle, World, WorldDef};
/// use janus2d_core::{BodyDef, Vec2};
/// use janus2d_core::geometry::Circle;
/// let mut world = World::new(WorldDef::default()).unwrap();
/// let b = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// let keep = world.create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, 1.0).unwrap()).unwrap();
/// let skip = world.create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.5).unwrap()).unwrap();
/// let only_keep = |s: ShapeHandle| s == keep;
/// let mut seen = Vec::new();
/// world.overlap_point(Vec2::ZERO, &QueryFilter::default().with_predicate(&only_keep), |o| { seen.push(o.shape); true });
/// assert_eq!(seen, vec![keep]);
/// assert_ne!(keep, skip);
/// ```
pub type QueryPredicate<'a> = &'a dyn Fn(ShapeHandle) -> bool;

/// Which shapes a query sees.
///
/// The lifetime is that of the [`predicate`](Self::predicate) closure it
/// may borrow; a filter without one is a `QueryFilter<'static>`.
#[derive(Clone, Copy)]
pub struct QueryFilter<'a> {
    /// The categories the query belongs to (usual 1).
    pub category_bits: u64,
    /// The categories the query sees (usual all).
    pub mask_bits: u64,
    /// A body whose shapes are skipped (usual none: the player casting from
    /// inside its own shape sets it).
    pub exclude_body: Option<BodyHandle>,
    /// Rays and shape casts continue through portal apertures (usual off).
    pub through_portals: bool,
    /// A last test of each shape that passed the others (usual none):
    /// `false` skips the shape. Called only for shapes the category, mask,
    /// body and sensor tests accept, before the exact geometric test.
    pub predicate: Option<QueryPredicate<'a>>,
}

impl Default for QueryFilter<'_> {
    fn default() -> Self {
        QueryFilter {
            category_bits: 1,
            mask_bits: u64::MAX,
            exclude_body: None,
            through_portals: false,
            predicate: None,
        }
    }
}

impl std::fmt::Debug for QueryFilter<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("QueryFilter")
            .field("category_bits", &self.category_bits)
            .field("mask_bits", &self.mask_bits)
            .field("exclude_body", &self.exclude_body)
            .field("through_portals", &self.through_portals)
            .field(
                "predicate",
                &self.predicate.map(|_| "Fn(ShapeHandle) -> bool"),
            )
            .finish()
    }
}

/// Two filters are equal when their fields are and their predicates are
/// both absent or the same closure (by address).
impl PartialEq for QueryFilter<'_> {
    fn eq(&self, other: &Self) -> bool {
        let same_predicate = match (self.predicate, other.predicate) {
            (None, None) => true,
            (Some(a), Some(b)) => std::ptr::addr_eq(a, b),
            _ => false,
        };
        self.category_bits == other.category_bits
            && self.mask_bits == other.mask_bits
            && self.exclude_body == other.exclude_body
            && self.through_portals == other.through_portals
            && same_predicate
    }
}

impl Eq for QueryFilter<'_> {}

impl<'a> QueryFilter<'a> {
    /// Sees only the categories in `mask_bits` (builder style).
    #[must_use]
    pub fn with_mask(mut self, mask_bits: u64) -> Self {
        self.mask_bits = mask_bits;
        self
    }

    /// Belongs to the categories in `category_bits` (builder style).
    ///
    /// ```
    /// use janus2d_world::QueryFilter;
    /// let f = QueryFilter::default().with_category(0b100);
    /// assert_eq!(f.category_bits, 4);
    /// ```
    #[must_use]
    pub fn with_category(mut self, category_bits: u64) -> Self {
        self.category_bits = category_bits;
        self
    }

    /// Skips the shapes of `body` (builder style).
    #[must_use]
    pub fn excluding(mut self, body: BodyHandle) -> Self {
        self.exclude_body = Some(body);
        self
    }

    /// Continues rays and shape casts through portal apertures (builder style).
    #[must_use]
    pub fn through_portals(mut self) -> Self {
        self.through_portals = true;
        self
    }

    /// Asks `predicate` about each shape the other tests accept; the query
    /// skips those it returns `false` for (builder style; as Rapier's
    /// `QueryFilter::predicate`). The closure is `Fn`: one that counts or
    /// records keeps its state in a `Cell` or `RefCell`.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let mut boxes = Vec::new();
    /// for x in [2.0, 4.0] {
    ///     let b = world.create_body(&BodyDef::fixed(Vec2::new(x, 0.0))).unwrap();
    ///     boxes.push(world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap());
    /// }
    /// // Skip the first box: the ray hits the second, at x = 3.5.
    /// let skip_first = |s| s != boxes[0];
    /// let filter = QueryFilter::default().with_predicate(&skip_first);
    /// let hit = world.cast_ray_closest(Vec2::ZERO, Vec2::new(10.0, 0.0), &filter).unwrap().unwrap();
    /// assert_eq!(hit.shape, boxes[1]);
    /// assert!((hit.point.x - 3.5).abs() < 1e-5);
    /// ```
    #[must_use]
    pub fn with_predicate<'b>(self, predicate: QueryPredicate<'b>) -> QueryFilter<'b> {
        QueryFilter {
            category_bits: self.category_bits,
            mask_bits: self.mask_bits,
            exclude_body: self.exclude_body,
            through_portals: self.through_portals,
            predicate: Some(predicate),
        }
    }

    /// Whether the query sees `shape` by category, mask, excluded body and
    /// sensor flag (the [`predicate`](Self::predicate) is not asked: it
    /// needs the handle, see [`accepts_shape`](Self::accepts_shape)).
    ///
    /// ```
    /// use janus2d_world::query::QueryFilter;
    /// let f = QueryFilter::default().with_mask(0b10);
    /// assert_eq!(f.mask_bits, 2);
    /// ```
    #[must_use]
    pub fn accepts(&self, shape: &ShapeData) -> bool {
        let f = &shape.def.filter;
        !shape.def.is_sensor
            && (f.category_bits & self.mask_bits) != 0
            && (f.mask_bits & self.category_bits) != 0
            && self.exclude_body != Some(shape.body)
    }

    /// Whether the query sees the shape `handle` with data `shape`: the
    /// tests of [`accepts`](Self::accepts), then the predicate.
    #[must_use]
    pub fn accepts_shape(&self, handle: ShapeHandle, shape: &ShapeData) -> bool {
        self.accepts(shape) && self.predicate.is_none_or(|p| p(handle))
    }
}

pub use crate::error::QueryProblem;

/// One portal aperture a ray went through.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PortalHop {
    /// The portal pair.
    pub pair: Handle<PortalPairTag>,
    /// The side entered: 0 for portal a, 1 for portal b.
    pub entered: usize,
    /// Where the ray crossed the entry aperture, world, m.
    pub entry_point: Vec2,
    /// Where it came out of the exit aperture, world, m.
    pub exit_point: Vec2,
}

/// A hit of a ray or a shape cast.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// The shape hit.
    pub shape: ShapeHandle,
    /// Its body.
    pub body: BodyHandle,
    /// The hit point on the shape's surface, world, m.
    pub point: Vec2,
    /// Unit surface normal of the shape hit at `point`, facing the ray.
    pub normal: Vec2,
    /// Fraction of the query's translation at the hit, in `[0, 1]`.
    pub fraction: Real,
    /// Portal apertures the ray went through before the hit (0 without portals).
    pub portal_hops: u32,
    /// The last aperture crossed, if any.
    pub last_portal: Option<PortalHop>,
}

/// A shape found by an overlap query.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShapeOverlap {
    /// The shape.
    pub shape: ShapeHandle,
    /// Its body.
    pub body: BodyHandle,
}

/// A portal aperture in world space, with the map to its partner.
#[derive(Clone, Copy, Debug)]
pub(crate) struct QueryAperture {
    pub(crate) pair: Handle<PortalPairTag>,
    pub(crate) side: usize,
    pub(crate) body: BodyHandle,
    pub(crate) half_width: Real,
    /// From this side (frame 1) to the partner (frame 2).
    pub(crate) map: PortalMap,
}

impl QueryAperture {
    /// True when `p` lies in the hole of the aperture: within its span and
    /// from just in front of the surface to `2w` behind it.
    fn holds(&self, p: Vec2) -> bool {
        let f = &self.map.frame1;
        let d = p - f.point;
        let s = d.dot(f.normal);
        cross(f.normal, d).abs() < self.half_width
            && s > -2.0 * self.half_width
            && s <= 2.0 * LINEAR_SLOP
    }
}

/// What the queries read: the shape store, the broadphase, the bodies and
/// (for `through_portals`) the apertures.
pub(crate) struct QueryContext<'a> {
    pub(crate) shapes: &'a ShapeStore,
    pub(crate) broadphase: &'a BroadPhase,
    pub(crate) bodies: &'a BodySet,
    pub(crate) owner: u32,
    pub(crate) apertures: Vec<QueryAperture>,
}

fn bad(field: &'static str, problem: QueryProblem) -> WorldError {
    WorldError::BadQuery { field, problem }
}

fn check_vec(v: Vec2, field: &'static str) -> Result<(), WorldError> {
    if vec_is_finite(v) {
        Ok(())
    } else {
        Err(bad(field, QueryProblem::NonFinite))
    }
}

fn check_translation(v: Vec2) -> Result<(), WorldError> {
    check_vec(v, "translation")?;
    if v.length_squared() > 0.0 {
        Ok(())
    } else {
        Err(bad("translation", QueryProblem::ZeroLength))
    }
}

/// A finite transform whose rotation is unit within the tolerance,
/// returned with its rotation normalised.
fn check_transform(xf: &Transform) -> Result<Transform, WorldError> {
    if !(vec_is_finite(xf.p) && xf.q.is_finite()) {
        return Err(bad("transform", QueryProblem::NonFinite));
    }
    let q =
        xf.q.to_unit()
            .ok_or(bad("transform", QueryProblem::NotUnitRotation))?;
    Ok(Transform { p: xf.p, q })
}

/// One straight piece of a cast: before the first aperture or after one.
#[derive(Clone, Copy, Debug)]
struct Leg {
    origin: Vec2,
    translation: Vec2,
    /// Global fraction where the leg starts (local 0); local 1 is global 1.
    start: Real,
    /// Rotation and scale applied to a cast shape by the apertures so far.
    rot: Rot,
    scale: Real,
    hops: u32,
    last: Option<PortalHop>,
}

impl Leg {
    fn global(&self, u: Real) -> Real {
        self.start + u * (1.0 - self.start)
    }
    fn local(&self, g: Real) -> Real {
        let span = 1.0 - self.start;
        if span > 0.0 {
            ((g - self.start) / span).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }
}

impl QueryContext<'_> {
    /// Whether `filter` (with its predicate) sees the shape in `slot`.
    fn admits(&self, filter: &QueryFilter, slot: u32) -> bool {
        filter.accepts_shape(
            self.shapes.handle_of(slot, self.owner),
            self.shapes.at(slot),
        )
    }

    fn transform_of(&self, body: BodyHandle) -> Transform {
        self.bodies
            .sim(body)
            .map_or(Transform::IDENTITY, |s| s.transform)
    }

    fn in_hole(&self, body: BodyHandle, p: Vec2) -> bool {
        self.apertures.iter().any(|a| a.body == body && a.holds(p))
    }

    /// The first aperture the leg's point crosses from the front within
    /// `max_u`: `(u, aperture index)`.
    fn first_aperture(&self, leg: &Leg, max_u: Real) -> Option<(Real, usize)> {
        let mut best: Option<(Real, usize)> = None;
        for (k, a) in self.apertures.iter().enumerate() {
            let f = &a.map.frame1;
            let dn = leg.translation.dot(f.normal);
            let s0 = (leg.origin - f.point).dot(f.normal);
            if dn >= 0.0 || s0 < 0.0 {
                continue;
            }
            let u = -s0 / dn;
            if u > max_u || best.is_some_and(|(b, _)| u >= b) {
                continue;
            }
            let x = leg.origin + u * leg.translation;
            if cross(f.normal, x - f.point).abs() < a.half_width {
                best = Some((u, k));
            }
        }
        best
    }

    /// The leg after aperture `k`, crossed at local fraction `u`.
    fn next_leg(&self, leg: &Leg, u: Real, k: usize) -> Leg {
        let a = &self.apertures[k];
        let x = leg.origin + u * leg.translation;
        let exit = a.map.map_point(x);
        Leg {
            origin: exit,
            translation: a.map.map_vector((1.0 - u) * leg.translation),
            start: leg.global(u),
            rot: a.map.rotation().mul(leg.rot),
            scale: leg.scale * a.map.eta,
            hops: leg.hops + 1,
            last: Some(PortalHop {
                pair: a.pair,
                entered: a.side,
                entry_point: x,
                exit_point: exit,
            }),
        }
    }

    /// Drops the hits on a portal body inside its aperture's hole.
    fn drop_hole_hits(&self, hits: &mut Vec<(Real, u32, CastHit)>) {
        hits.retain(|(_, slot, h)| !self.in_hole(self.shapes.at(*slot).body, h.point));
    }

    /// The accepted shape of `body` whose surface is within
    /// [`LINEAR_SLOP`] of `point` (the nearest; ties by slot).
    fn shape_at(&self, body: BodyHandle, point: Vec2, filter: &QueryFilter) -> Option<u32> {
        let probe = ShapeProxy::point(point);
        let mut best: Option<(Real, u32)> = None;
        for &slot in self.shapes.of_body(body) {
            let data = self.shapes.at(slot);
            if !self.admits(filter, slot) {
                continue;
            }
            let d = janus2d_core::geometry::shape_distance(
                &ShapeProxy::from_shape(&data.geometry),
                &self.transform_of(body),
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

    /// Runs the legs of a cast: `gather(leg, max_u, may_cross, out)` pushes
    /// the exact hits `(local fraction, shape slot, hit)` of one leg (without
    /// those in an aperture's hole when `may_cross`); they are sorted and
    /// handed to `callback` with the clipping rules of the module docs.
    fn run_cast<G, F>(
        &self,
        origin: Vec2,
        translation: Vec2,
        filter: &QueryFilter,
        mut gather: G,
        mut callback: F,
    ) where
        G: FnMut(&Leg, Real, bool, &mut Vec<(Real, u32, CastHit)>),
        F: FnMut(&RayHit) -> Real,
    {
        let mut leg = Leg {
            origin,
            translation,
            start: 0.0,
            rot: Rot::IDENTITY,
            scale: 1.0,
            hops: 0,
            last: None,
        };
        let mut max_fraction: Real = 1.0;
        let mut hits: Vec<(Real, u32, CastHit)> = Vec::new();
        loop {
            let max_u = leg.local(max_fraction);
            // After the last allowed hop the apertures are walls again.
            let may_cross = filter.through_portals && leg.hops < MAX_PORTAL_HOPS;
            let portal = if may_cross {
                self.first_aperture(&leg, max_u)
            } else {
                None
            };
            let limit = portal.map_or(max_u, |(u, _)| u);
            hits.clear();
            gather(&leg, limit, may_cross, &mut hits);
            // One hit per shape (its first), then nearest first.
            hits.sort_by(|a, b| a.1.cmp(&b.1).then(a.0.total_cmp(&b.0)));
            hits.dedup_by_key(|h| h.1);
            hits.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for &(u, slot, h) in &hits {
                let fraction = leg.global(u);
                if fraction > max_fraction {
                    continue;
                }
                let data = self.shapes.at(slot);
                let hit = RayHit {
                    shape: self.shapes.handle_of(slot, self.owner),
                    body: data.body,
                    point: h.point,
                    normal: h.normal,
                    fraction,
                    portal_hops: leg.hops,
                    last_portal: leg.last,
                };
                let r = callback(&hit);
                if r == 0.0 {
                    return;
                }
                if r > 0.0 && r < max_fraction {
                    max_fraction = r;
                }
            }
            match portal {
                Some((u, k)) if leg.global(u) < max_fraction && u < 1.0 => {
                    leg = self.next_leg(&leg, u, k);
                }
                _ => return,
            }
        }
    }
}

/// Every hit of the ray `origin + s · translation`, `s ∈ [0, 1]`, to
/// `callback` (see the module docs for its return value).
pub(crate) fn cast_ray<F: FnMut(&RayHit) -> Real>(
    ctx: &QueryContext<'_>,
    origin: Vec2,
    translation: Vec2,
    filter: &QueryFilter,
    callback: F,
) -> Result<(), WorldError> {
    check_vec(origin, "origin")?;
    check_translation(translation)?;
    let gather = |leg: &Leg, max_u: Real, may_cross: bool, out: &mut Vec<(Real, u32, CastHit)>| {
        let ray = RayInput {
            origin: leg.origin,
            translation: leg.translation,
            max_fraction: max_u,
        };
        ctx.broadphase
            .ray_query(leg.origin, leg.translation, max_u, |_, slot| {
                let data = ctx.shapes.at(slot);
                if ctx.admits(filter, slot)
                    && let Some(h) = data.geometry.ray_cast(&ctx.transform_of(data.body), &ray)
                {
                    out.push((h.fraction, slot, h));
                }
                true
            });
        if may_cross {
            ctx.drop_hole_hits(out);
        }
    };
    ctx.run_cast(origin, translation, filter, gather, callback);
    Ok(())
}

/// Every hit of `shape`, placed by `xf`, swept along `translation`.
pub(crate) fn cast_shape<F: FnMut(&RayHit) -> Real>(
    ctx: &QueryContext<'_>,
    shape: &Shape,
    xf: &Transform,
    translation: Vec2,
    filter: &QueryFilter,
    callback: F,
) -> Result<(), WorldError> {
    shape
        .validate()
        .map_err(|e| bad("shape", QueryProblem::Shape(e)))?;
    let xf = &check_transform(xf)?;
    check_translation(translation)?;
    let gather = |leg: &Leg, max_u: Real, may_cross: bool, out: &mut Vec<(Real, u32, CastHit)>| {
        let caster = if leg.scale == 1.0 {
            *shape
        } else {
            shape.scaled(leg.scale, Vec2::ZERO)
        };
        let start = Transform {
            p: leg.origin,
            q: leg.rot.mul(xf.q),
        };
        let end = Transform {
            p: leg.origin + max_u * leg.translation,
            q: start.q,
        };
        let swept = caster
            .compute_aabb(&start)
            .union(&caster.compute_aabb(&end));
        let proxy_b = ShapeProxy::from_shape(&caster);
        let centre = start.apply(caster.centroid());
        ctx.broadphase.query(&swept, |_, slot| {
            let data = ctx.shapes.at(slot);
            if !ctx.admits(filter, slot) {
                return true;
            }
            let xf_a = ctx.transform_of(data.body);
            if let Shape::ChainSegment(c) = &data.geometry {
                // One-sided: a caster starting behind the segment passes.
                let p1 = xf_a.apply(c.segment.point1);
                if (centre - p1).dot(xf_a.q.rotate(c.normal())) < 0.0 {
                    return true;
                }
            }
            let proxy_a = ShapeProxy::from_shape(&data.geometry);
            if let Some(h) = shape_cast(&proxy_a, &xf_a, &proxy_b, &start, leg.translation, max_u) {
                out.push((h.fraction, slot, h));
            }
            true
        });
        if may_cross {
            ctx.drop_hole_hits(out);
            // The lips: a shape too wide for an aperture meets its two end
            // points (where the hole meets the wall surface) first.
            for a in &ctx.apertures {
                let f = &a.map.frame1;
                for side in [-1.0, 1.0] {
                    let corner = f.point + side * a.half_width * f.tangent;
                    let lip = ShapeProxy::point(corner);
                    let hit = shape_cast(
                        &lip,
                        &Transform::IDENTITY,
                        &proxy_b,
                        &start,
                        leg.translation,
                        max_u,
                    );
                    if let Some(h) = hit
                        && let Some(slot) = ctx.shape_at(a.body, corner, filter)
                    {
                        out.push((h.fraction, slot, h));
                    }
                }
            }
        }
    };
    ctx.run_cast(xf.p, translation, filter, gather, callback);
    Ok(())
}

/// Calls `callback` for the accepted shapes among `candidates` (slots, any
/// order, duplicates allowed) that `exact` says overlap, in slot order,
/// until it returns `false`.
fn report_overlaps<F: FnMut(ShapeOverlap) -> bool>(
    ctx: &QueryContext<'_>,
    mut candidates: Vec<u32>,
    filter: &QueryFilter,
    exact: impl Fn(&ShapeData, &Transform) -> bool,
    mut callback: F,
) {
    candidates.sort_unstable();
    candidates.dedup();
    for slot in candidates {
        let data = ctx.shapes.at(slot);
        if !ctx.admits(filter, slot) || !exact(data, &ctx.transform_of(data.body)) {
            continue;
        }
        let overlap = ShapeOverlap {
            shape: ctx.shapes.handle_of(slot, ctx.owner),
            body: data.body,
        };
        if !callback(overlap) {
            return;
        }
    }
}

fn candidates_in(ctx: &QueryContext<'_>, aabb: &Aabb) -> Vec<u32> {
    let mut out = Vec::new();
    ctx.broadphase.query(aabb, |_, slot| {
        out.push(slot);
        true
    });
    out
}

/// The shapes whose surface meets `aabb`.
pub(crate) fn overlap_aabb<F: FnMut(ShapeOverlap) -> bool>(
    ctx: &QueryContext<'_>,
    aabb: &Aabb,
    filter: &QueryFilter,
    callback: F,
) -> Result<(), WorldError> {
    check_vec(aabb.lower, "aabb")?;
    check_vec(aabb.upper, "aabb")?;
    if !aabb.is_valid() {
        return Err(bad("aabb", QueryProblem::Inverted));
    }
    let boxed = ShapeProxy::from_box(aabb.lower, aabb.upper);
    let exact = |data: &ShapeData, xf: &Transform| {
        let p = ShapeProxy::from_shape(&data.geometry);
        shapes_overlap(&p, xf, &boxed, &Transform::IDENTITY)
    };
    report_overlaps(ctx, candidates_in(ctx, aabb), filter, exact, callback);
    Ok(())
}

/// The shapes that touch or overlap `shape` placed by `xf`.
pub(crate) fn overlap_shape<F: FnMut(ShapeOverlap) -> bool>(
    ctx: &QueryContext<'_>,
    shape: &Shape,
    xf: &Transform,
    filter: &QueryFilter,
    callback: F,
) -> Result<(), WorldError> {
    shape
        .validate()
        .map_err(|e| bad("shape", QueryProblem::Shape(e)))?;
    let xf = &check_transform(xf)?;
    let proxy = ShapeProxy::from_shape(shape);
    let exact = |data: &ShapeData, xf_a: &Transform| {
        let p = ShapeProxy::from_shape(&data.geometry);
        shapes_overlap(&p, xf_a, &proxy, xf)
    };
    let aabb = shape.compute_aabb(xf);
    report_overlaps(ctx, candidates_in(ctx, &aabb), filter, exact, callback);
    Ok(())
}

/// The solid shapes (not segments) that contain `point`.
pub(crate) fn overlap_point<F: FnMut(ShapeOverlap) -> bool>(
    ctx: &QueryContext<'_>,
    point: Vec2,
    filter: &QueryFilter,
    callback: F,
) -> Result<(), WorldError> {
    check_vec(point, "point")?;
    let probe = ShapeProxy::point(point);
    let exact = |data: &ShapeData, xf: &Transform| {
        if matches!(data.geometry, Shape::Segment(_) | Shape::ChainSegment(_)) {
            return false;
        }
        let p = ShapeProxy::from_shape(&data.geometry);
        shapes_overlap(&p, xf, &probe, &Transform::IDENTITY)
    };
    let aabb = Aabb::new(point, point);
    report_overlaps(ctx, candidates_in(ctx, &aabb), filter, exact, callback);
    Ok(())
}

/// Distance and closest points between two live shapes (slots).
pub(crate) fn distance_between(ctx: &QueryContext<'_>, a: u32, b: u32) -> DistanceOutput {
    let (da, db) = (ctx.shapes.at(a), ctx.shapes.at(b));
    janus2d_core::geometry::shape_distance(
        &ShapeProxy::from_shape(&da.geometry),
        &ctx.transform_of(da.body),
        &ShapeProxy::from_shape(&db.geometry),
        &ctx.transform_of(db.body),
    )
}

/// The point on a shape's surface nearest to a query point
/// ([`World::project_point`](crate::World::project_point)).
///
/// ```
/// use janus2d_world::{QueryFilter, ShapeDef, World, WorldDef};
/// use janus2d_core::{BodyDef, Vec2};
/// use janus2d_core::geometry::Polygon;
/// let mut world = World::new(WorldDef::default()).unwrap();
/// let b = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(1.0, 1.0)).unwrap();
/// let p = world.project_point(Vec2::new(3.0, 0.5), 10.0, &QueryFilter::default()).unwrap().unwrap();
/// assert_eq!((p.point, p.normal, p.distance, p.inside), (Vec2::new(1.0, 0.5), Vec2::X, 2.0, false));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointProjection {
    /// The shape.
    pub shape: ShapeHandle,
    /// Its body.
    pub body: BodyHandle,
    /// The nearest point of the shape's surface, world, m.
    pub point: Vec2,
    /// Unit outward surface normal at `point` (for a query point on a
    /// segment's or a core's line itself, the shape's own side normal).
    pub normal: Vec2,
    /// Distance from the query point to `point`, m (≥ 0; the depth when
    /// `inside`).
    pub distance: Real,
    /// The query point lies inside the (solid) shape: deeper than 0 under
    /// its surface. Segments and chain segments never hold a point.
    pub inside: bool,
}

/// Nearest point on the segment `a`–`b` to `p`.
fn closest_on_segment(a: Vec2, b: Vec2, p: Vec2) -> Vec2 {
    let d = b - a;
    let dd = d.length_squared();
    if dd <= 0.0 {
        return a;
    }
    let t = ((p - a).dot(d) / dd).clamp(0.0, 1.0);
    a + t * d
}

/// The unit right perpendicular of `b - a` (`(0, -1)` for a point).
fn side_normal(a: Vec2, b: Vec2) -> Vec2 {
    let d = b - a;
    let len = d.length();
    if len > 0.0 {
        Vec2::new(d.y, -d.x) / len
    } else {
        Vec2::new(0.0, -1.0)
    }
}

/// Surface point, outward normal and signed distance (negative inside) of
/// a core `core` (the nearest core point to `p`) rounded by `radius`;
/// `fallback` is the normal when `p` is on the core itself.
fn rounded(core: Vec2, p: Vec2, radius: Real, fallback: Vec2) -> (Vec2, Vec2, Real) {
    let d = p - core;
    let len = d.length();
    let n = if len > 0.0 { d / len } else { fallback };
    (core + radius * n, n, len - radius)
}

/// `(surface point, outward normal, signed distance)` of `shape` from
/// `p`, all in the shape's frame; the distance is negative inside.
pub(crate) fn project_local(shape: &Shape, p: Vec2) -> (Vec2, Vec2, Real) {
    match shape {
        Shape::Circle(c) => rounded(c.center, p, c.radius, Vec2::Y),
        Shape::Capsule(c) => {
            let core = closest_on_segment(c.center1, c.center2, p);
            rounded(core, p, c.radius, side_normal(c.center1, c.center2))
        }
        Shape::Segment(s) => {
            let core = closest_on_segment(s.point1, s.point2, p);
            let (q, n, d) = rounded(core, p, 0.0, side_normal(s.point1, s.point2));
            (q, n, d.max(0.0))
        }
        Shape::ChainSegment(c) => {
            let s = &c.segment;
            let core = closest_on_segment(s.point1, s.point2, p);
            let (q, n, d) = rounded(core, p, 0.0, side_normal(s.point1, s.point2));
            (q, n, d.max(0.0))
        }
        Shape::Polygon(poly) => {
            let n = poly.count;
            if n < 3 {
                let (a, b) = (poly.vertices[0], poly.vertices[1.min(n - 1)]);
                let core = closest_on_segment(a, b, p);
                return rounded(core, p, poly.radius, poly.normals[0]);
            }
            // The face the point is farthest out of.
            let mut best = (Real::NEG_INFINITY, 0);
            for i in 0..n {
                let s = poly.normals[i].dot(p - poly.vertices[i]);
                if s > best.0 {
                    best = (s, i);
                }
            }
            let (s, face) = best;
            if s <= 0.0 {
                // Inside the core: straight out through the nearest face.
                let normal = poly.normals[face];
                return (p + (poly.radius - s) * normal, normal, s - poly.radius);
            }
            // Outside the core: the nearest point of its boundary.
            let mut nearest = (Real::INFINITY, Vec2::ZERO, 0);
            for i in 0..n {
                let q = closest_on_segment(poly.vertices[i], poly.vertices[(i + 1) % n], p);
                let d2 = (p - q).length_squared();
                if d2 < nearest.0 {
                    nearest = (d2, q, i);
                }
            }
            rounded(nearest.1, p, poly.radius, poly.normals[nearest.2])
        }
    }
}

/// The projection of `p` (world) on the shape in `slot` at its body's pose.
fn project_slot(ctx: &QueryContext<'_>, slot: u32, p: Vec2) -> PointProjection {
    let data = ctx.shapes.at(slot);
    let xf = ctx.transform_of(data.body);
    let (q, n, signed) = project_local(&data.geometry, xf.apply_inv(p));
    PointProjection {
        shape: ctx.shapes.handle_of(slot, ctx.owner),
        body: data.body,
        point: xf.apply(q),
        normal: xf.q.rotate(n),
        distance: signed.abs(),
        inside: signed < 0.0,
    }
}

/// The accepted shape whose surface is nearest to `point` within
/// `max_distance` (shapes holding the point first, the deepest first).
pub(crate) fn project_point(
    ctx: &QueryContext<'_>,
    point: Vec2,
    max_distance: Real,
    filter: &QueryFilter,
) -> Result<Option<PointProjection>, WorldError> {
    check_vec(point, "point")?;
    if max_distance.is_nan() {
        return Err(bad("max_distance", QueryProblem::NonFinite));
    }
    if max_distance < 0.0 {
        return Err(bad("max_distance", QueryProblem::Negative));
    }
    let reach = Vec2::new(max_distance, max_distance);
    let aabb = Aabb::new(point - reach, point + reach);
    let mut candidates = candidates_in(ctx, &aabb);
    candidates.sort_unstable();
    candidates.dedup();
    let mut best: Option<(Real, PointProjection)> = None;
    for slot in candidates {
        if !ctx.admits(filter, slot) {
            continue;
        }
        let proj = project_slot(ctx, slot, point);
        let signed = if proj.inside {
            -proj.distance
        } else {
            proj.distance
        };
        if signed > max_distance {
            continue;
        }
        if best.is_none_or(|(b, _)| signed < b) {
            best = Some((signed, proj));
        }
    }
    Ok(best.map(|(_, p)| p))
}

/// The projection of `point` on one live shape (slot), unfiltered.
pub(crate) fn project_on_shape(
    ctx: &QueryContext<'_>,
    slot: u32,
    point: Vec2,
) -> Result<PointProjection, WorldError> {
    check_vec(point, "point")?;
    Ok(project_slot(ctx, slot, point))
}

/// The first hit of the ray on the shape in `slot` only (when `filter`
/// accepts it), through apertures when the filter says so.
pub(crate) fn shape_ray_cast(
    ctx: &QueryContext<'_>,
    slot: u32,
    origin: Vec2,
    translation: Vec2,
    filter: &QueryFilter,
) -> Result<Option<RayHit>, WorldError> {
    check_vec(origin, "origin")?;
    check_translation(translation)?;
    if !ctx.admits(filter, slot) {
        return Ok(None);
    }
    let data = ctx.shapes.at(slot);
    let gather = |leg: &Leg, max_u: Real, may_cross: bool, out: &mut Vec<(Real, u32, CastHit)>| {
        let ray = RayInput {
            origin: leg.origin,
            translation: leg.translation,
            max_fraction: max_u,
        };
        if let Some(h) = data.geometry.ray_cast(&ctx.transform_of(data.body), &ray) {
            out.push((h.fraction, slot, h));
        }
        if may_cross {
            ctx.drop_hole_hits(out);
        }
    };
    let mut best = None;
    ctx.run_cast(origin, translation, filter, gather, |hit| {
        best = Some(*hit);
        0.0
    });
    Ok(best)
}

/// Whether the solid shape in `slot` holds `point` (as `overlap_point`'s
/// exact test; segments never do).
pub(crate) fn shape_test_point(
    ctx: &QueryContext<'_>,
    slot: u32,
    point: Vec2,
) -> Result<bool, WorldError> {
    check_vec(point, "point")?;
    let data = ctx.shapes.at(slot);
    if matches!(data.geometry, Shape::Segment(_) | Shape::ChainSegment(_)) {
        return Ok(false);
    }
    let p = ShapeProxy::from_shape(&data.geometry);
    Ok(shapes_overlap(
        &p,
        &ctx.transform_of(data.body),
        &ShapeProxy::point(point),
        &Transform::IDENTITY,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use janus2d_constraints::portal_map::PortalFrame;

    fn v(x: Real, y: Real) -> Vec2 {
        Vec2::new(x, y)
    }

    fn aperture(point: Vec2, normal: Vec2, half_width: Real) -> QueryAperture {
        QueryAperture {
            pair: Handle::new(0, 1, 0),
            side: 0,
            body: BodyHandle::new(0, 1, 0),
            half_width,
            map: PortalMap {
                frame1: PortalFrame::from_point_normal(point, normal),
                frame2: PortalFrame::from_point_normal(v(10.0, 0.0), Vec2::Y),
                eta: 2.0,
            },
        }
    }

    #[test]
    fn aperture_hole_spans_the_width_and_twice_it_in_depth() {
        // Aperture at the origin facing −x, half-width 1: the wall is at x > 0.
        let a = aperture(Vec2::ZERO, -Vec2::X, 1.0);
        assert!(a.holds(v(0.0, 0.9)));
        assert!(!a.holds(v(0.0, 1.1)), "the lips are not the hole");
        assert!(a.holds(v(1.9, 0.0)), "2w deep behind the surface");
        assert!(!a.holds(v(2.1, 0.0)));
        assert!(
            !a.holds(v(-0.1, 0.0)),
            "in front of the surface is not the hole"
        );
    }

    #[test]
    fn leg_fractions_map_back_to_the_original_translation() {
        let leg = Leg {
            origin: Vec2::ZERO,
            translation: Vec2::X,
            start: 0.5,
            rot: Rot::IDENTITY,
            scale: 1.0,
            hops: 1,
            last: None,
        };
        assert_eq!(leg.global(0.0), 0.5);
        assert_eq!(leg.global(1.0), 1.0);
        assert!((leg.global(0.4) - 0.7).abs() < 1e-6);
        assert!((leg.local(0.7) - 0.4).abs() < 1e-6);
        assert_eq!(leg.local(0.2), 0.0, "before the leg clamps to its start");
    }

    #[test]
    fn next_leg_maps_point_direction_length_turn_and_scale() {
        // Entry facing −x at the origin; exit facing +y at (10, 0), η = 2.
        let (shapes, broadphase, bodies) =
            (ShapeStore::default(), BroadPhase::new(), BodySet::new());
        let ctx = QueryContext {
            shapes: &shapes,
            broadphase: &broadphase,
            bodies: &bodies,
            owner: bodies.owner(),
            apertures: vec![aperture(Vec2::ZERO, -Vec2::X, 1.0)],
        };
        let leg = Leg {
            origin: v(-4.0, 0.5),
            translation: v(8.0, 0.0),
            start: 0.0,
            rot: Rot::IDENTITY,
            scale: 1.0,
            hops: 0,
            last: None,
        };
        let (u, k) = ctx.first_aperture(&leg, 1.0).unwrap();
        assert!((u - 0.5).abs() < 1e-6);
        // Too short to reach it, or outside its span: no crossing.
        assert!(ctx.first_aperture(&leg, 0.49).is_none());
        let high = Leg {
            origin: v(-4.0, 1.5),
            ..leg
        };
        assert!(ctx.first_aperture(&high, 1.0).is_none());
        let next = ctx.next_leg(&leg, u, k);
        // Q takes the entry normal (−x) to minus the exit normal (−y): a
        // quarter turn anticlockwise; the offset +0.5 y maps to 2 · (−0.5, 0).
        assert!((next.origin - v(9.0, 0.0)).length() < 1e-5, "{next:?}");
        // The 4 m left become 8 m along +y (out of the exit).
        assert!((next.translation - v(0.0, 8.0)).length() < 1e-5);
        assert!((next.start - 0.5).abs() < 1e-6);
        assert!((next.rot.angle() - janus2d_core::math::PI / 2.0).abs() < 1e-5);
        assert_eq!((next.scale, next.hops), (2.0, 1));
        let hop = next.last.unwrap();
        assert!((hop.entry_point - v(0.0, 0.5)).length() < 1e-6);
        // Leaving the exit along +n: the exit aperture is not crossed again.
        let mut back = ctx;
        back.apertures = vec![aperture(v(9.0, 0.0), Vec2::Y, 2.0)];
        assert!(back.first_aperture(&next, 1.0).is_none());
    }

    #[test]
    fn filter_accepts_by_category_mask_body_and_sensor() {
        use crate::shapes::{Filter, ShapeDef};
        let body = BodyHandle::new(3, 1, 0);
        let data = |category_bits: u64, is_sensor: bool| ShapeData {
            body,
            geometry: Shape::Circle(janus2d_core::geometry::Circle {
                center: Vec2::ZERO,
                radius: 1.0,
            }),
            def: ShapeDef {
                filter: Filter {
                    category_bits,
                    ..Filter::default()
                },
                is_sensor,
                ..ShapeDef::default()
            },
            proxy: 0,
            aabb: Aabb::default(),
        };
        let f = QueryFilter::default();
        assert!(f.accepts(&data(1, false)));
        assert!(!f.accepts(&data(1, true)), "sensors are not seen");
        assert!(!f.with_mask(0b10).accepts(&data(1, false)));
        assert!(f.with_mask(0b10).accepts(&data(0b10, false)));
        assert!(!f.excluding(body).accepts(&data(1, false)));
    }
}
