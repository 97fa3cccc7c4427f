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
//! | `shape_distance`                   | distance and closest points of two shapes     | [`shape_distance`] |
//!
//! **Rules shared by every query.**
//! - A shape is tested when [`QueryFilter::accepts`] it: category/mask as
//!   Box2D (`shape.category & query.mask != 0` and `shape.mask &
//!   query.category != 0`), not on the excluded body, not a sensor.
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
//! is not hit inside the aperture (the hole of the portal clipping). Each hit
//! reports how many apertures it went through ([`RayHit::portal_hops`]) and
//! the last one ([`RayHit::last_portal`]); fractions stay those of the
//! original translation. At most [`MAX_PORTAL_HOPS`] apertures are crossed.

use janus2d_constraints::portal_map::PortalMap;
use janus2d_core::body::{BodyHandle, BodySet};
use janus2d_core::geometry::{
    Aabb, CastHit, DistanceOutput, GeometryError, LINEAR_SLOP, RayInput, Shape, ShapeProxy,
    shape_cast, shapes_overlap,
};
use janus2d_core::handle::{Handle, PortalPairTag};
use janus2d_core::math::{Real, Rot, Transform, Vec2, cross, vec_is_finite};

use crate::broadphase::BroadPhase;
use crate::error::WorldError;
use crate::shapes::{ShapeData, ShapeHandle, ShapeStore};

#[cfg(doc)]
use janus2d_core::geometry::shape_distance;

/// Most portal apertures one ray or shape cast goes through (a count; usual 4).
pub const MAX_PORTAL_HOPS: u32 = 4;

/// Which shapes a query sees.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct QueryFilter {
    /// The categories the query belongs to (usual 1).
    pub category_bits: u64,
    /// The categories the query sees (usual all).
    pub mask_bits: u64,
    /// A body whose shapes are skipped (usual none: the player casting from
    /// inside its own shape sets it).
    pub exclude_body: Option<BodyHandle>,
    /// Rays and shape casts continue through portal apertures (usual off).
    pub through_portals: bool,
}

impl Default for QueryFilter {
    fn default() -> Self {
        QueryFilter {
            category_bits: 1,
            mask_bits: u64::MAX,
            exclude_body: None,
            through_portals: false,
        }
    }
}

impl QueryFilter {
    /// Sees only the categories in `mask_bits` (builder style).
    #[must_use]
    pub fn with_mask(mut self, mask_bits: u64) -> Self {
        self.mask_bits = mask_bits;
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

    /// Whether the query sees `shape`.
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
}

/// What is wrong with a query input ([`WorldError::BadQuery`]).
#[derive(Clone, Debug, PartialEq)]
pub enum QueryProblem {
    /// A coordinate is NaN or infinite.
    NonFinite,
    /// A translation of zero length (a ray or cast needs a direction).
    ZeroLength,
    /// A box whose lower corner is above its upper corner.
    Inverted,
    /// The query shape is invalid.
    Shape(GeometryError),
}

impl std::fmt::Display for QueryProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            QueryProblem::NonFinite => write!(f, "is not finite"),
            QueryProblem::ZeroLength => write!(f, "has zero length"),
            QueryProblem::Inverted => write!(f, "has its lower corner above its upper corner"),
            QueryProblem::Shape(e) => write!(f, "is an invalid shape: {e}"),
        }
    }
}

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

fn check_transform(xf: &Transform) -> Result<(), WorldError> {
    if vec_is_finite(xf.p) && xf.q.is_finite() {
        Ok(())
    } else {
        Err(bad("transform", QueryProblem::NonFinite))
    }
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

    /// Runs the legs of a cast: `gather(leg, max_u, out)` pushes the exact
    /// hits `(local fraction, shape slot, hit)` of one leg; they are sorted
    /// and handed to `callback` with the clipping rules of the module docs.
    fn run_cast<G, F>(
        &self,
        origin: Vec2,
        translation: Vec2,
        filter: &QueryFilter,
        mut gather: G,
        mut callback: F,
    ) where
        G: FnMut(&Leg, Real, &mut Vec<(Real, u32, CastHit)>),
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
            let portal = if filter.through_portals && leg.hops < MAX_PORTAL_HOPS {
                self.first_aperture(&leg, max_u)
            } else {
                None
            };
            let limit = portal.map_or(max_u, |(u, _)| u);
            hits.clear();
            gather(&leg, limit, &mut hits);
            if filter.through_portals {
                hits.retain(|(_, slot, h)| !self.in_hole(self.shapes.at(*slot).body, h.point));
            }
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
    let gather = |leg: &Leg, max_u: Real, out: &mut Vec<(Real, u32, CastHit)>| {
        let ray = RayInput {
            origin: leg.origin,
            translation: leg.translation,
            max_fraction: max_u,
        };
        ctx.broadphase
            .ray_query(leg.origin, leg.translation, max_u, |_, slot| {
                let data = ctx.shapes.at(slot);
                if filter.accepts(data)
                    && let Some(h) = data.geometry.ray_cast(&ctx.transform_of(data.body), &ray)
                {
                    out.push((h.fraction, slot, h));
                }
                true
            });
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
    check_transform(xf)?;
    check_translation(translation)?;
    let gather = |leg: &Leg, max_u: Real, out: &mut Vec<(Real, u32, CastHit)>| {
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
            if !filter.accepts(data) {
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
        if !filter.accepts(data) || !exact(data, &ctx.transform_of(data.body)) {
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
    check_transform(xf)?;
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
