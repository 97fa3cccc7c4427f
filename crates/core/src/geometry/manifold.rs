//! Contact manifolds: up to two contact points between two shapes.
//!
//! Conventions:
//! - [`Manifold::normal`] is a world unit vector pointing from shape A to
//!   shape B;
//! - [`ManifoldPoint::point`] is midway between the two surfaces;
//!   `anchor_a = point - xf_a.p` and `anchor_b = point - xf_b.p` (world-aligned
//!   offsets from the body origins, not from the centres of mass);
//! - `separation` is the signed gap along the normal, negative when
//!   overlapping; a point is reported when `separation < speculative_distance`;
//! - feature ids are `(feature_a << 8) | feature_b` (see [`feature_id`]),
//!   where a feature is a vertex or edge index of that shape; swapping A and B
//!   swaps the two bytes.
//!
//! Every computation happens in A's local frame (polygons: shifted to A's
//! first vertex) and is then mapped to the world, which keeps results
//! accurate far from the world origin. No heap allocation.

use super::shapes::{
    ChainSegment, Circle, LINEAR_SLOP, MAX_POLYGON_VERTICES, Polygon, Shape, WELD_DISTANCE,
    normalize_or, right_perp,
};
use crate::math::{EPSILON, Real, Transform, Vec2, cross};

/// Capsule–capsule: the two cores count as parallel (two contact points)
/// when the sine of the angle between them is below this (dimensionless;
/// usual value 0.05, about 2.9°).
pub const CAPSULE_PARALLEL_SINE: Real = 0.05;

/// Chain segments: a contact normal whose tangential component
/// `|dot(normal, segment direction)|` is at most this counts as the segment's
/// face normal and is always accepted (dimensionless sine; usual value 0.01,
/// about 0.6°).
pub const CHAIN_FACE_SINE: Real = 0.01;

/// Polygon–polygon: B's face is the reference face only when its separation
/// beats A's by more than this, in metres (usual value 0.0005 m = 0.1 ×
/// [`LINEAR_SLOP`]); the bias keeps the choice from flickering between steps.
pub const REFERENCE_FACE_TOLERANCE: Real = 0.1 * LINEAR_SLOP;

/// One contact point.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ManifoldPoint {
    /// World point midway between the two surfaces.
    pub point: Vec2,
    /// Contact point relative to body A's transform origin `xf_a.p`, world-aligned.
    pub anchor_a: Vec2,
    /// Contact point relative to body B's transform origin `xf_b.p`, world-aligned.
    pub anchor_b: Vec2,
    /// Signed separation along the normal (negative = penetration), metres.
    pub separation: Real,
    /// Feature id: stays the same while the same features touch (for warm starting).
    pub id: u16,
}

impl ManifoldPoint {
    const ZERO: ManifoldPoint = ManifoldPoint {
        point: Vec2::ZERO,
        anchor_a: Vec2::ZERO,
        anchor_b: Vec2::ZERO,
        separation: 0.0,
        id: 0,
    };
}

/// The contact between two shapes: a shared normal and up to two points.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Manifold {
    /// Unit normal in world space, pointing from A to B (zero when empty).
    pub normal: Vec2,
    /// Contact points; only the first `point_count` are meaningful.
    pub points: [ManifoldPoint; 2],
    /// Number of contact points (0, 1 or 2).
    pub point_count: usize,
}

impl Manifold {
    /// No contact.
    pub const EMPTY: Manifold = Manifold {
        normal: Vec2::ZERO,
        points: [ManifoldPoint::ZERO; 2],
        point_count: 0,
    };

    /// The meaningful contact points.
    #[inline]
    pub fn points(&self) -> &[ManifoldPoint] {
        &self.points[..self.point_count]
    }

    /// True when there is no contact point.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.point_count == 0
    }

    /// The same contact seen with A and B swapped: the normal is negated,
    /// anchors are exchanged and the two bytes of every feature id are swapped.
    #[inline]
    pub fn flipped(&self) -> Manifold {
        let mut m = *self;
        m.normal = -m.normal;
        for p in &mut m.points[..m.point_count] {
            std::mem::swap(&mut p.anchor_a, &mut p.anchor_b);
            p.id = p.id.swap_bytes();
        }
        m
    }

    /// Appends a point given in A's local frame.
    #[inline(always)]
    fn push_local(&mut self, xf_a: &Transform, d_ab: Vec2, local: Vec2, separation: Real, id: u16) {
        let anchor_a = xf_a.q.rotate(local);
        self.points[self.point_count] = ManifoldPoint {
            point: xf_a.p + anchor_a,
            anchor_a,
            anchor_b: anchor_a + d_ab,
            separation,
            id,
        };
        self.point_count += 1;
    }
}

/// Feature id of a contact point: `(feature_a << 8) | feature_b`, each
/// feature a vertex/edge index below 256.
#[inline(always)]
pub fn feature_id(feature_a: usize, feature_b: usize) -> u16 {
    (((feature_a & 0xff) << 8) | (feature_b & 0xff)) as u16
}

/// [`collide`], and when the manifold is empty because the shapes lie
/// apart along one of their faces' normals (or along the line between a
/// circle's centre and its nearest feature), that separation less the
/// radii, m: the *clearance*. Otherwise (points found, or a pair without
/// such a test) the clearance is 0.
///
/// The clearance is a lower bound on the test it comes from: while no
/// point of either shape moves by more than `m` relative to the other
/// (`m = |Δp| + 2 |sin(Δθ / 2)| R`, the relative translation plus the turn
/// at the moving shape's reach `R`), the same test gives at least
/// `clearance − m`, so the manifold stays empty while
/// `clearance − m > speculative_distance`. The narrowphase keeps empty
/// manifolds that way without testing again (as Box2D v3.2 recycles the
/// non-touching ones, but exact: a kept empty manifold is the one the test
/// would give).
///
/// ```
/// use janus2d_core::geometry::{Polygon, Shape, collide_with_clearance};
/// use janus2d_core::math::{Rot, Transform, Vec2};
/// let b = Shape::Polygon(Polygon::make_box(0.5, 0.5));
/// let xf_a = Transform::IDENTITY;
/// let xf_b = Transform { p: Vec2::new(1.3, 0.0), q: Rot::IDENTITY };
/// let (m, clearance) = collide_with_clearance(&b, &xf_a, &b, &xf_b, 0.02);
/// assert_eq!(m.point_count, 0);
/// assert!((clearance - 0.3).abs() < 1e-5);
/// ```
#[must_use]
#[inline]
pub fn collide_with_clearance(
    shape_a: &Shape,
    xf_a: &Transform,
    shape_b: &Shape,
    xf_b: &Transform,
    speculative_distance: Real,
) -> (Manifold, Real) {
    let mut clearance = 0.0;
    let m = collide_into(
        shape_a,
        xf_a,
        shape_b,
        xf_b,
        speculative_distance,
        &mut clearance,
    );
    (m, clearance)
}

/// Contact manifold between two shapes placed by `xf_a` and `xf_b`.
///
/// Points are reported when their separation is below
/// `speculative_distance` (usually [`SPECULATIVE_DISTANCE`](super::SPECULATIVE_DISTANCE)).
/// See the module docs for the conventions and [`super`] for which routine
/// handles which pair. Deterministic; never NaN for valid shapes.
#[must_use]
pub fn collide(
    shape_a: &Shape,
    xf_a: &Transform,
    shape_b: &Shape,
    xf_b: &Transform,
    speculative_distance: Real,
) -> Manifold {
    collide_into(shape_a, xf_a, shape_b, xf_b, speculative_distance, &mut 0.0)
}

/// The dispatch of [`collide`]; writes the clearance
/// ([`collide_with_clearance`]) where a routine's test ends it.
fn collide_into(
    shape_a: &Shape,
    xf_a: &Transform,
    shape_b: &Shape,
    xf_b: &Transform,
    speculative_distance: Real,
    clear: &mut Real,
) -> Manifold {
    use Shape as S;
    let spec = speculative_distance;
    match (shape_a, shape_b) {
        // Circle against anything.
        (S::Circle(a), S::Circle(b)) => collide_circles(a, xf_a, b, xf_b, spec, clear),
        (S::Capsule(a), S::Circle(b)) => {
            collide_capsule_circle(a.center1, a.center2, a.radius, xf_a, b, xf_b, spec, clear)
        }
        (S::Segment(a), S::Circle(b)) => {
            collide_capsule_circle(a.point1, a.point2, 0.0, xf_a, b, xf_b, spec, clear)
        }
        (S::Polygon(a), S::Circle(b)) => collide_polygon_circle(a, xf_a, b, xf_b, spec, clear),
        (S::ChainSegment(a), S::Circle(b)) => collide_chain_circle(a, xf_a, b, xf_b, spec),
        (S::Circle(_), _) => collide_into(shape_b, xf_b, shape_a, xf_a, spec, clear).flipped(),

        // Capsule / segment pairs: closest points of the two cores.
        (S::Capsule(a), S::Capsule(b)) => collide_capsules(
            a.center1, a.center2, a.radius, xf_a, b.center1, b.center2, b.radius, xf_b, spec, clear,
        ),
        (S::Capsule(a), S::Segment(b)) => collide_capsules(
            a.center1, a.center2, a.radius, xf_a, b.point1, b.point2, 0.0, xf_b, spec, clear,
        ),
        (S::Segment(a), S::Capsule(b)) => collide_capsules(
            a.point1, a.point2, 0.0, xf_a, b.center1, b.center2, b.radius, xf_b, spec, clear,
        ),
        (S::Segment(a), S::Segment(b)) => collide_capsules(
            a.point1, a.point2, 0.0, xf_a, b.point1, b.point2, 0.0, xf_b, spec, clear,
        ),

        // Polygon pairs (capsules and segments as 2-vertex polygons).
        (S::Polygon(a), S::Polygon(b)) => collide_polygons_inner(a, xf_a, b, xf_b, spec, clear),
        (S::Polygon(a), S::Capsule(_) | S::Segment(_)) => {
            collide_polygons_inner(a, xf_a, &as_polygon(shape_b), xf_b, spec, clear)
        }
        (S::Capsule(_) | S::Segment(_), S::Polygon(b)) => {
            collide_polygons_inner(&as_polygon(shape_a), xf_a, b, xf_b, spec, clear)
        }

        // One-sided chain segments (one-sided: no clearance).
        (S::ChainSegment(a), S::ChainSegment(b)) => collide_chains(a, xf_a, b, xf_b, spec),
        (S::ChainSegment(a), _) => collide_chain_polygon(a, xf_a, &as_polygon(shape_b), xf_b, spec),
        (_, S::ChainSegment(b)) => {
            collide_chain_polygon(b, xf_b, &as_polygon(shape_a), xf_a, spec).flipped()
        }
    }
}

/// The polygon form of a polygonal shape (capsules and segments become
/// 2-vertex polygons). Circles and chain segments never reach this.
#[inline]
fn as_polygon(s: &Shape) -> Polygon {
    match s {
        Shape::Polygon(p) => *p,
        Shape::Capsule(c) => Polygon::make_capsule(c.center1, c.center2, c.radius),
        Shape::Segment(g) => Polygon::make_capsule(g.point1, g.point2, 0.0),
        Shape::ChainSegment(c) => Polygon::make_capsule(c.segment.point1, c.segment.point2, 0.0),
        Shape::Circle(c) => Polygon::make_capsule(c.center, c.center, c.radius),
    }
}

// ---------------------------------------------------------------------------
// Point-like features.
// ---------------------------------------------------------------------------

/// Contact between a disc of radius `ra` at `pa` and one of radius `rb` at
/// `pb`, both in A's local frame. `fallback` (unit) is the normal used when
/// the centres coincide. `clear`: the clearance where the discs are apart
/// (their distance less the radii, which a motion of either centre by `m`
/// changes by at most `m`).
#[inline]
#[allow(clippy::too_many_arguments)]
fn point_contact(
    xf_a: &Transform,
    xf_b: &Transform,
    pa: Vec2,
    ra: Real,
    pb: Vec2,
    rb: Real,
    fallback: Vec2,
    spec: Real,
    id: u16,
    clear: &mut Real,
) -> Manifold {
    let d = pb - pa;
    let dist_sq = d.length_squared();
    let max = ra + rb + spec;
    if dist_sq >= max * max {
        *clear = dist_sq.sqrt() - ra - rb;
        return Manifold::EMPTY;
    }
    let dist = dist_sq.sqrt();
    let normal = if dist > EPSILON { d / dist } else { fallback };
    let separation = dist - ra - rb;
    if separation >= spec {
        *clear = separation;
        return Manifold::EMPTY;
    }
    let ca = pa + ra * normal;
    let cb = pb - rb * normal;
    let mut m = Manifold {
        normal: xf_a.q.rotate(normal),
        ..Manifold::EMPTY
    };
    m.push_local(xf_a, xf_a.p - xf_b.p, 0.5 * (ca + cb), separation, id);
    m
}

/// Circle–circle. Coincident centres get A's local +y as normal.
fn collide_circles(
    a: &Circle,
    xf_a: &Transform,
    b: &Circle,
    xf_b: &Transform,
    spec: Real,
    clear: &mut Real,
) -> Manifold {
    let xf = xf_a.inv_mul(xf_b);
    let pb = xf.apply(b.center);
    point_contact(
        xf_a,
        xf_b,
        a.center,
        a.radius,
        pb,
        b.radius,
        Vec2::new(0.0, 1.0),
        spec,
        0,
        clear,
    )
}

/// Capsule (core `a1`–`a2`, radius `ra`; a segment when `ra == 0`) against a
/// circle: closest point on the core. Feature id: 0.
fn collide_capsule_circle(
    a1: Vec2,
    a2: Vec2,
    ra: Real,
    xf_a: &Transform,
    b: &Circle,
    xf_b: &Transform,
    spec: Real,
    clear: &mut Real,
) -> Manifold {
    let xf = xf_a.inv_mul(xf_b);
    let c = xf.apply(b.center);
    let e = a2 - a1;
    let ee = e.length_squared();
    let t = if ee > 0.0 {
        ((c - a1).dot(e) / ee).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = a1 + t * e;
    let fallback = normalize_or(e, Vec2::new(1.0, 0.0)).perp();
    point_contact(xf_a, xf_b, q, ra, c, b.radius, fallback, spec, 0, clear)
}

/// Polygon–circle: the edge of greatest separation, then its vertex or face
/// region. Feature id: 0.
fn collide_polygon_circle(
    a: &Polygon,
    xf_a: &Transform,
    b: &Circle,
    xf_b: &Transform,
    spec: Real,
    clear: &mut Real,
) -> Manifold {
    let xf = xf_a.inv_mul(xf_b);
    let c = xf.apply(b.center);
    let radius = a.radius + b.radius;
    let n = a.count;
    let mut best = 0;
    let mut separation = Real::NEG_INFINITY;
    for i in 0..n {
        let s = a.normals[i].dot(c - a.vertices[i]);
        if s > separation {
            separation = s;
            best = i;
        }
    }
    if separation - radius > spec {
        // (The largest face separation of the centre: a motion of it by
        // `m` changes it by at most `m`. The vertex regions' empty ends
        // give none: the next test may take the face.)
        *clear = separation - radius;
        return Manifold::EMPTY;
    }
    let v1 = a.vertices[best];
    let v2 = a.vertices[if best + 1 < n { best + 1 } else { 0 }];
    let u1 = (c - v1).dot(v2 - v1);
    let u2 = (c - v2).dot(v1 - v2);
    if u1 < 0.0 && separation > EPSILON {
        // Vertex region of v1.
        point_contact(
            xf_a,
            xf_b,
            v1,
            a.radius,
            c,
            b.radius,
            a.normals[best],
            spec,
            0,
            &mut 0.0,
        )
    } else if u2 < 0.0 && separation > EPSILON {
        // Vertex region of v2.
        point_contact(
            xf_a,
            xf_b,
            v2,
            a.radius,
            c,
            b.radius,
            a.normals[best],
            spec,
            0,
            &mut 0.0,
        )
    } else {
        // Face region (also when the centre is inside).
        let normal = a.normals[best];
        let sep = separation - radius;
        if sep >= spec {
            return Manifold::EMPTY;
        }
        let ca = c + (a.radius - separation) * normal;
        let cb = c - b.radius * normal;
        let mut m = Manifold {
            normal: xf_a.q.rotate(normal),
            ..Manifold::EMPTY
        };
        m.push_local(xf_a, xf_a.p - xf_b.p, 0.5 * (ca + cb), sep, 0);
        m
    }
}

// ---------------------------------------------------------------------------
// Segment closest points and capsules.
// ---------------------------------------------------------------------------

/// Closest points of segments `p1`–`q1` and `p2`–`q2`: `c1 = p1 + s (q1 - p1)`,
/// `c2 = p2 + t (q2 - p2)`. End points give exactly `s`/`t` ∈ {0, 1}.
#[derive(Clone, Copy, Debug)]
struct SegmentDistance {
    c1: Vec2,
    c2: Vec2,
    s: Real,
    t: Real,
    dist_sq: Real,
}

#[inline]
fn segment_distance(p1: Vec2, q1: Vec2, p2: Vec2, q2: Vec2) -> SegmentDistance {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.length_squared();
    let e = d2.length_squared();
    let f = d2.dot(r);
    let tiny = EPSILON * EPSILON;
    let (s, t);
    if a <= tiny && e <= tiny {
        s = 0.0;
        t = 0.0;
    } else if a <= tiny {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= tiny {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s1 = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t1 = (b * s1 + f) / e;
            if t1 < 0.0 {
                t1 = 0.0;
                s1 = (-c / a).clamp(0.0, 1.0);
            } else if t1 > 1.0 {
                t1 = 1.0;
                s1 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s1;
            t = t1;
        }
    }
    let c1 = p1 + s * d1;
    let c2 = p2 + t * d2;
    SegmentDistance {
        c1,
        c2,
        s,
        t,
        dist_sq: c1.distance_squared(c2),
    }
}

/// Feature index along a core: 0 at the first end, 1 at the second, 2 inside.
#[inline(always)]
fn end_feature(f: Real) -> usize {
    if f == 0.0 {
        0
    } else if f == 1.0 {
        1
    } else {
        2
    }
}

/// Capsule–capsule (either may be a segment with radius 0).
///
/// Nearly parallel cores ([`CAPSULE_PARALLEL_SINE`]) that overlap along A's
/// axis give two points: B's core clipped to A's extent, normal perpendicular
/// to A, ids `feature_id(2, k)` for B's end `k`. Otherwise one point at the
/// closest points of the cores, id `feature_id(fa, fb)` with 0/1 for an end
/// and 2 for the interior.
fn collide_capsules(
    a1: Vec2,
    a2: Vec2,
    ra: Real,
    xf_a: &Transform,
    b1: Vec2,
    b2: Vec2,
    rb: Real,
    xf_b: &Transform,
    spec: Real,
    clear: &mut Real,
) -> Manifold {
    let xf = xf_a.inv_mul(xf_b);
    // A's frame shifted to a1.
    let origin = a1;
    let p1 = Vec2::ZERO;
    let q1 = a2 - origin;
    let p2 = xf.apply(b1) - origin;
    let q2 = xf.apply(b2) - origin;
    let sd = segment_distance(p1, q1, p2, q2);
    let radius = ra + rb;
    let max = radius + spec;
    if sd.dist_sq >= max * max {
        // (The cores' distance: a motion of either by `m` changes it by at
        // most `m`.)
        *clear = sd.dist_sq.sqrt() - radius;
        return Manifold::EMPTY;
    }
    let d_ab = xf_a.p - xf_b.p;
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let len1_sq = d1.length_squared();
    let len2_sq = d2.length_squared();
    let mid_delta = 0.5 * (p2 + q2) - 0.5 * (p1 + q1);

    if len1_sq > LINEAR_SLOP * LINEAR_SLOP && len2_sq > LINEAR_SLOP * LINEAR_SLOP {
        let len1 = len1_sq.sqrt();
        let u1 = d1 / len1;
        let sine = cross(u1, d2) / len2_sq.sqrt();
        if sine.abs() < CAPSULE_PARALLEL_SINE {
            let mut n = u1.perp();
            let side = n.dot(sd.c2 - sd.c1);
            let side = if side != 0.0 { side } else { n.dot(mid_delta) };
            if side < 0.0 {
                n = -n;
            }
            let tp = p2.dot(u1);
            let tq = q2.dot(u1);
            let lo = tp.min(tq).max(0.0);
            let hi = tp.max(tq).min(len1);
            let dt = tq - tp;
            if hi - lo > LINEAR_SLOP && dt.abs() > EPSILON {
                let mut m = Manifold::EMPTY;
                for (k, tx) in [(0usize, tp), (1usize, tq)] {
                    let v = p2 + ((tx.clamp(0.0, len1) - tp) / dt) * d2;
                    let dist = n.dot(v);
                    let sep = dist - radius;
                    if sep < spec {
                        let ca = v + (ra - dist) * n;
                        let cb = v - rb * n;
                        m.push_local(xf_a, d_ab, 0.5 * (ca + cb) + origin, sep, feature_id(2, k));
                    }
                }
                if m.point_count > 0 {
                    m.normal = xf_a.q.rotate(n);
                    return m;
                }
            }
        }
    }

    // One point at the closest points of the cores.
    let dist = sd.dist_sq.sqrt();
    let normal = if dist > EPSILON {
        (sd.c2 - sd.c1) / dist
    } else {
        // Crossing cores: perpendicular to A (or B), towards B's middle.
        let axis = if len1_sq > EPSILON * EPSILON { d1 } else { d2 };
        let n = normalize_or(axis, Vec2::new(1.0, 0.0)).perp();
        if n.dot(mid_delta) < 0.0 { -n } else { n }
    };
    let separation = dist - radius;
    if separation >= spec {
        return Manifold::EMPTY;
    }
    let ca = sd.c1 + ra * normal;
    let cb = sd.c2 - rb * normal;
    let mut m = Manifold {
        normal: xf_a.q.rotate(normal),
        ..Manifold::EMPTY
    };
    let id = feature_id(end_feature(sd.s), end_feature(sd.t));
    m.push_local(xf_a, d_ab, 0.5 * (ca + cb) + origin, separation, id);
    m
}

// ---------------------------------------------------------------------------
// Polygons.
// ---------------------------------------------------------------------------

/// Polygon vertices and normals expressed in a shared frame.
#[derive(Clone, Copy)]
struct LocalPolygon {
    v: [Vec2; MAX_POLYGON_VERTICES],
    n: [Vec2; MAX_POLYGON_VERTICES],
    count: usize,
    radius: Real,
}

/// The edge of `p1` with the greatest separation from `p2` (core shapes):
/// `max_i min_j dot(n1_i, v2_j - v1_i)`.
#[inline]
fn find_max_separation(p1: &LocalPolygon, p2: &LocalPolygon) -> (usize, Real) {
    let mut best = 0;
    let mut best_sep = Real::NEG_INFINITY;
    for i in 0..p1.count {
        let n = p1.n[i];
        let v1 = p1.v[i];
        let mut si = Real::INFINITY;
        for j in 0..p2.count {
            let s = n.dot(p2.v[j] - v1);
            if s < si {
                si = s;
            }
        }
        if si > best_sep {
            best_sep = si;
            best = i;
        }
    }
    (best, best_sep)
}

#[inline(always)]
fn next_index(i: usize, count: usize) -> usize {
    if i + 1 < count { i + 1 } else { 0 }
}

/// Polygon–polygon (Box2D v3 style), rounding radii included.
///
/// SAT on both polygons picks the reference face (B's only when it is better
/// by [`REFERENCE_FACE_TOLERANCE`]); the incident edge is the other polygon's
/// edge most anti-parallel to it. When the cores are apart by more than
/// 0.1 × [`LINEAR_SLOP`] and the closest features of the two edges are two
/// vertices, one point with the vertex–vertex normal is produced (id: the two
/// vertex indices); otherwise the incident edge is clipped to the reference
/// edge, giving points with ids `(i11, i22)` and `(i12, i21)` (reference edge
/// vertices `i11 → i12`, incident edge `i21 → i22`, written A-first).
#[inline]
pub(crate) fn collide_polygons(
    pa: &Polygon,
    xf_a: &Transform,
    pb: &Polygon,
    xf_b: &Transform,
    spec: Real,
) -> Manifold {
    collide_polygons_inner(pa, xf_a, pb, xf_b, spec, &mut 0.0)
}

/// The polygon routine; writes the clearance where a separating-axis
/// test ends it.
fn collide_polygons_inner(
    pa: &Polygon,
    xf_a: &Transform,
    pb: &Polygon,
    xf_b: &Transform,
    spec: Real,
    clearance: &mut Real,
) -> Manifold {
    let origin = pa.vertices[0];
    let xf = xf_a.inv_mul(xf_b);
    let mut la = LocalPolygon {
        v: pa.vertices,
        n: pa.normals,
        count: pa.count,
        radius: pa.radius,
    };
    for i in 0..pa.count {
        la.v[i] -= origin;
    }
    // B in A's frame, shifted by the same origin.
    let shift = xf.p - origin;
    let mut lb = LocalPolygon {
        v: pb.vertices,
        n: pb.normals,
        count: pb.count,
        radius: pb.radius,
    };
    for i in 0..pb.count {
        lb.v[i] = xf.q.rotate(lb.v[i]) + shift;
        lb.n[i] = xf.q.rotate(lb.n[i]);
    }
    let radius = pa.radius + pb.radius;

    let (edge_a, sep_a) = find_max_separation(&la, &lb);
    if sep_a - radius > spec {
        *clearance = sep_a - radius;
        return Manifold::EMPTY;
    }
    let (edge_b, sep_b) = find_max_separation(&lb, &la);
    if sep_b - radius > spec {
        *clearance = sep_b - radius;
        return Manifold::EMPTY;
    }

    let flip = sep_b > sep_a + REFERENCE_FACE_TOLERANCE;
    let (p1, p2, i11, separation) = if flip {
        (&lb, &la, edge_b, sep_b)
    } else {
        (&la, &lb, edge_a, sep_a)
    };
    let i12 = next_index(i11, p1.count);
    let n = p1.n[i11];

    // Incident edge: the edge of p2 most anti-parallel to n.
    let mut i21 = 0;
    let mut min_dot = Real::INFINITY;
    for i in 0..p2.count {
        let d = n.dot(p2.n[i]);
        if d < min_dot {
            min_dot = d;
            i21 = i;
        }
    }
    let i22 = next_index(i21, p2.count);

    let v11 = p1.v[i11];
    let v12 = p1.v[i12];
    let v21 = p2.v[i21];
    let v22 = p2.v[i22];
    let d_ab = xf_a.p - xf_b.p;

    if separation > REFERENCE_FACE_TOLERANCE {
        let sd = segment_distance(v11, v12, v21, v22);
        let vertex1 = sd.s == 0.0 || sd.s == 1.0;
        let vertex2 = sd.t == 0.0 || sd.t == 1.0;
        if vertex1 && vertex2 {
            // Vertex–vertex: the true closest direction, not a face normal.
            let dist = sd.dist_sq.sqrt();
            let sep = dist - radius;
            if sep >= spec || dist.is_nan() || dist <= 0.0 {
                return Manifold::EMPTY;
            }
            let normal = (sd.c2 - sd.c1) / dist;
            let ca = sd.c1 + p1.radius * normal;
            let cb = sd.c2 - p2.radius * normal;
            let f1 = if sd.s == 0.0 { i11 } else { i12 };
            let f2 = if sd.t == 0.0 { i21 } else { i22 };
            let (normal, id) = if flip {
                (-normal, feature_id(f2, f1))
            } else {
                (normal, feature_id(f1, f2))
            };
            let mut m = Manifold {
                normal: xf_a.q.rotate(normal),
                ..Manifold::EMPTY
            };
            m.push_local(xf_a, d_ab, 0.5 * (ca + cb) + origin, sep, id);
            return m;
        }
    }

    // Clip the incident edge to the side planes of the reference edge.
    let tangent = n.perp();
    let upper1 = (v12 - v11).dot(tangent);
    let upper2 = (v21 - v11).dot(tangent);
    let lower2 = (v22 - v11).dot(tangent);
    let span = upper2 - lower2;
    let mut v_lower = v22;
    let mut v_upper = v21;
    if span > EPSILON {
        if lower2 < 0.0 {
            v_lower = v22.lerp(v21, (-lower2 / span).min(1.0));
        }
        if upper2 > upper1 {
            v_upper = v22.lerp(v21, ((upper1 - lower2) / span).max(0.0));
        }
    }
    let s_lower = (v_lower - v11).dot(n);
    let s_upper = (v_upper - v11).dot(n);
    // Move to the middle between the two rounded surfaces.
    let half_r = 0.5 * (p1.radius - p2.radius);
    let m_lower = v_lower + (half_r - 0.5 * s_lower) * n + origin;
    let m_upper = v_upper + (half_r - 0.5 * s_upper) * n + origin;
    let s_lower = s_lower - radius;
    let s_upper = s_upper - radius;

    // The normal is written first and the manifold built in place: setting
    // it after the points made the return copy stall on a partial store.
    let mut m = Manifold {
        normal: xf_a.q.rotate(if flip { -n } else { n }),
        ..Manifold::EMPTY
    };
    if flip {
        if s_upper < spec {
            m.push_local(xf_a, d_ab, m_upper, s_upper, feature_id(i21, i12));
        }
        if s_lower < spec {
            m.push_local(xf_a, d_ab, m_lower, s_lower, feature_id(i22, i11));
        }
    } else {
        if s_lower < spec {
            m.push_local(xf_a, d_ab, m_lower, s_lower, feature_id(i11, i22));
        }
        if s_upper < spec {
            m.push_local(xf_a, d_ab, m_upper, s_upper, feature_id(i12, i21));
        }
    }
    if m.point_count == 0 {
        return Manifold::EMPTY;
    }
    m
}

// ---------------------------------------------------------------------------
// Chain segments.
// ---------------------------------------------------------------------------

/// Unit direction of a chain's neighbouring edge, or `None` when the ghost is
/// within the weld distance of the end point (no neighbour).
#[inline]
fn neighbour_direction(edge: Vec2) -> Option<Vec2> {
    let len = edge.length();
    if len > WELD_DISTANCE {
        Some(edge / len)
    } else {
        None
    }
}

/// Whether chain segment `c` accepts a contact with local normal `nl`
/// (pointing from the segment to the other shape).
///
/// The normal must point to the front side. A face normal (within
/// [`CHAIN_FACE_SINE`]) is accepted. A normal tilted towards an end belongs
/// to that end's vertex: with no neighbour it is accepted; at a convex vertex
/// it is accepted when it is closer to this segment's normal than to the
/// neighbour's (the neighbour takes the other half of the vertex cone; ties
/// go to the segment starting at the vertex); at a straight or concave
/// vertex it is rejected (the neighbour's face handles it). This is what
/// stops a box sliding along a chain from catching on internal vertices.
fn chain_admits(c: &ChainSegment, nl: Vec2) -> bool {
    let p1 = c.segment.point1;
    let p2 = c.segment.point2;
    let e = p2 - p1;
    let len = e.length();
    if len.is_nan() || len <= EPSILON {
        return false;
    }
    let u1 = e / len;
    let n1 = right_perp(u1);
    if nl.dot(n1) < 0.0 {
        return false;
    }
    let t = nl.dot(u1);
    if t.abs() <= CHAIN_FACE_SINE {
        return true;
    }
    if t < 0.0 {
        match neighbour_direction(p1 - c.ghost1) {
            None => true,
            Some(u0) => cross(u0, u1) > 0.0 && nl.dot(n1) >= nl.dot(right_perp(u0)),
        }
    } else {
        match neighbour_direction(c.ghost2 - p2) {
            None => true,
            Some(u2) => cross(u1, u2) > 0.0 && nl.dot(n1) > nl.dot(right_perp(u2)),
        }
    }
}

/// True when local point `p` is behind the chain segment (strictly on the
/// back side of its line).
#[inline]
fn chain_behind(c: &ChainSegment, p: Vec2) -> bool {
    let e = c.segment.point2 - c.segment.point1;
    right_perp(e).dot(p - c.segment.point1) < 0.0
}

/// Chain segment–circle: no contact when the centre is behind; the closest
/// point on the segment otherwise. A contact at an end vertex is kept by only
/// one of the two segments sharing it: the vertex's plane is split by the sum
/// of the two edge directions, the segment starting at the vertex taking the
/// side the sum points to (and ties). Feature id: 0.
fn collide_chain_circle(
    a: &ChainSegment,
    xf_a: &Transform,
    b: &Circle,
    xf_b: &Transform,
    spec: Real,
) -> Manifold {
    let xf = xf_a.inv_mul(xf_b);
    let c = xf.apply(b.center);
    let p1 = a.segment.point1;
    let p2 = a.segment.point2;
    let e = p2 - p1;
    let ee = e.length_squared();
    if ee.is_nan() || ee <= EPSILON * EPSILON || chain_behind(a, c) {
        return Manifold::EMPTY;
    }
    let u1 = e / ee.sqrt();
    let u = (c - p1).dot(e) / ee;
    let q = if u <= 0.0 {
        if let Some(u0) = neighbour_direction(p1 - a.ghost1)
            && (c - p1).dot(u0 + u1) < 0.0
        {
            return Manifold::EMPTY;
        }
        p1
    } else if u >= 1.0 {
        if let Some(u2) = neighbour_direction(a.ghost2 - p2)
            && (c - p2).dot(u1 + u2) >= 0.0
        {
            return Manifold::EMPTY;
        }
        p2
    } else {
        p1 + u * e
    };
    point_contact(
        xf_a,
        xf_b,
        q,
        0.0,
        c,
        b.radius,
        right_perp(u1),
        spec,
        0,
        &mut 0.0,
    )
}

/// Chain segment–polygon (capsules and segments as 2-vertex polygons): no
/// contact when the polygon's centroid is behind; otherwise the
/// segment-as-polygon manifold, dropped unless [`chain_admits`] its normal.
fn collide_chain_polygon(
    a: &ChainSegment,
    xf_a: &Transform,
    pb: &Polygon,
    xf_b: &Transform,
    spec: Real,
) -> Manifold {
    let xf = xf_a.inv_mul(xf_b);
    if chain_behind(a, xf.apply(pb.centroid)) {
        return Manifold::EMPTY;
    }
    let seg = Polygon::make_capsule(a.segment.point1, a.segment.point2, 0.0);
    let m = collide_polygons(&seg, xf_a, pb, xf_b, spec);
    if m.point_count == 0 {
        return m;
    }
    if !chain_admits(a, xf_a.q.inv_rotate(m.normal)) {
        // The separating axis belongs to a vertex the neighbour handles, or
        // to a face of the polygon (a polygon pressed deep into the chain
        // turns its own face normal into the best axis): contact along this
        // segment's own face where the polygon lies over it. Dropping it
        // instead let a polygon pressed into a concave corner of a loop
        // through the wall, neither segment holding it.
        return chain_face_manifold(a, xf_a, pb, xf_b, spec);
    }
    m
}

/// The manifold of a polygon against chain segment `a` with the segment's
/// front normal as the reference face: the polygon's edge most
/// anti-parallel to it, clipped to the segment's extent (empty when the
/// polygon does not lie over the segment). Feature ids: `(0, i22)` and
/// `(1, i21)`, as a reference edge `0 → 1`.
fn chain_face_manifold(
    a: &ChainSegment,
    xf_a: &Transform,
    pb: &Polygon,
    xf_b: &Transform,
    spec: Real,
) -> Manifold {
    let xf = xf_a.inv_mul(xf_b);
    let (p1, p2) = (a.segment.point1, a.segment.point2);
    let e = p2 - p1;
    let len = e.length();
    if len.is_nan() || len <= EPSILON {
        return Manifold::EMPTY;
    }
    let u1 = e / len;
    let n1 = right_perp(u1);
    let mut i21 = 0;
    let mut min_dot = Real::INFINITY;
    for i in 0..pb.count {
        let d = n1.dot(xf.q.rotate(pb.normals[i]));
        if d < min_dot {
            min_dot = d;
            i21 = i;
        }
    }
    let i22 = next_index(i21, pb.count);
    let v21 = xf.apply(pb.vertices[i21]);
    let v22 = xf.apply(pb.vertices[i22]);
    let (t21, t22) = ((v21 - p1).dot(u1), (v22 - p1).dot(u1));
    // The incident edge runs against the reference edge: v22 is the lower.
    let (lower, upper) = (t22.min(t21), t22.max(t21));
    if upper < 0.0 || lower > len {
        return Manifold::EMPTY;
    }
    let at = |t: Real| {
        let span = t21 - t22;
        if span.abs() > EPSILON {
            v22.lerp(v21, ((t - t22) / span).clamp(0.0, 1.0))
        } else {
            v22
        }
    };
    let v_lower = at(lower.max(0.0));
    let v_upper = at(upper.min(len));
    let d_ab = xf_a.p - xf_b.p;
    let mut m = Manifold::EMPTY;
    for (v, id) in [(v_lower, feature_id(0, i22)), (v_upper, feature_id(1, i21))] {
        let s_core = (v - p1).dot(n1);
        let separation = s_core - pb.radius;
        if separation < spec {
            let mid = v - 0.5 * (s_core + pb.radius) * n1;
            m.push_local(xf_a, d_ab, mid, separation, id);
        }
    }
    if m.point_count > 0 {
        m.normal = xf_a.q.rotate(n1);
    }
    m
}

/// Chain segment–chain segment: [`collide_chain_polygon`] with B as a
/// segment, also requiring A's midpoint in front of B and B to admit the
/// (reversed) normal.
fn collide_chains(
    a: &ChainSegment,
    xf_a: &Transform,
    b: &ChainSegment,
    xf_b: &Transform,
    spec: Real,
) -> Manifold {
    let pb = Polygon::make_capsule(b.segment.point1, b.segment.point2, 0.0);
    let m = collide_chain_polygon(a, xf_a, &pb, xf_b, spec);
    if m.point_count == 0 {
        return m;
    }
    let mid_a = xf_b.apply_inv(xf_a.apply(0.5 * (a.segment.point1 + a.segment.point2)));
    if chain_behind(b, mid_a) || !chain_admits(b, xf_b.q.inv_rotate(-m.normal)) {
        return Manifold::EMPTY;
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::SPECULATIVE_DISTANCE;
    use crate::geometry::shapes::{Capsule, Segment, make_chain};
    use crate::math::PI;

    /// Absolute tolerance in metres: 1e-5 holds in f32, 1e-10 in f64 (the
    /// scenes here are within a few metres of the origin).
    #[cfg(not(feature = "f64"))]
    const TOL: Real = 1e-5;
    #[cfg(feature = "f64")]
    const TOL: Real = 1e-10;

    const SPEC: Real = SPECULATIVE_DISTANCE;

    fn v(x: Real, y: Real) -> Vec2 {
        Vec2::new(x, y)
    }

    fn xf(x: Real, y: Real, angle: Real) -> Transform {
        Transform::new(v(x, y), angle)
    }

    fn near(a: Vec2, b: Vec2, tol: Real) -> bool {
        (a - b).length() <= tol
    }

    /// Checks the frame conventions of every point.
    fn check_conventions(m: &Manifold, xf_a: &Transform, xf_b: &Transform) {
        if m.point_count == 0 {
            return;
        }
        assert!(
            (m.normal.length() - 1.0).abs() < 10.0 * TOL,
            "normal {:?}",
            m.normal
        );
        for p in m.points() {
            assert!(near(p.anchor_a + xf_a.p, p.point, 10.0 * TOL));
            assert!(near(p.anchor_b + xf_b.p, p.point, 10.0 * TOL));
            assert!(p.separation < SPEC);
            assert!(p.point.is_finite() && p.separation.is_finite());
        }
    }

    fn boxes(h: Real) -> Shape {
        Shape::Polygon(Polygon::make_box(h, h))
    }

    #[test]
    fn box_resting_on_box() {
        let a = Shape::Polygon(Polygon::make_box(5.0, 0.5));
        let b = boxes(0.5);
        let (xa, xb) = (xf(0.0, 0.0, 0.0), xf(0.3, 1.0, 0.0));
        let m = collide(&a, &xa, &b, &xb, SPEC);
        check_conventions(&m, &xa, &xb);
        assert_eq!(m.point_count, 2);
        assert!(near(m.normal, v(0.0, 1.0), TOL));
        let mut xs: Vec<Real> = m.points().iter().map(|p| p.point.x).collect();
        xs.sort_by(Real::total_cmp);
        assert!(
            (xs[0] + 0.2).abs() < TOL && (xs[1] - 0.8).abs() < TOL,
            "{xs:?}"
        );
        for p in m.points() {
            assert!(p.separation.abs() < TOL);
            assert!((p.point.y - 0.5).abs() < TOL);
        }
        assert_ne!(m.points[0].id, m.points[1].id);

        // Swapped order: same points, reversed normal, swapped ids.
        let r = collide(&b, &xb, &a, &xa, SPEC);
        check_conventions(&r, &xb, &xa);
        assert_eq!(r.point_count, 2);
        assert!(near(r.normal, v(0.0, -1.0), TOL));
        let ids: Vec<u16> = m.points().iter().map(|p| p.id).collect();
        for p in r.points() {
            assert!(ids.contains(&p.id.swap_bytes()), "{ids:?} vs {}", p.id);
        }
    }

    #[test]
    fn overlapping_and_speculative_boxes() {
        let (a, b) = (boxes(0.5), boxes(0.5));
        let xa = xf(0.0, 0.0, 0.0);
        // 0.05 m overlap.
        let xb = xf(0.1, 0.95, 0.0);
        let m = collide(&a, &xa, &b, &xb, SPEC);
        check_conventions(&m, &xa, &xb);
        assert_eq!(m.point_count, 2);
        for p in m.points() {
            assert!((p.separation + 0.05).abs() < TOL, "{}", p.separation);
            // Midway between the surfaces: y = 0.5 - 0.025.
            assert!((p.point.y - 0.475).abs() < TOL);
        }
        // 0.01 m gap: speculative points with positive separation.
        let xb = xf(0.1, 1.01, 0.0);
        let m = collide(&a, &xa, &b, &xb, SPEC);
        assert_eq!(m.point_count, 2);
        for p in m.points() {
            assert!((p.separation - 0.01).abs() < TOL);
        }
        // Beyond the speculative distance: nothing.
        let xb = xf(0.1, 1.0 + SPEC + 0.001, 0.0);
        assert!(collide(&a, &xa, &b, &xb, SPEC).is_empty());
    }

    #[test]
    fn feature_ids_stable_under_small_motion() {
        let (a, b) = (boxes(0.5), boxes(0.5));
        let xa = xf(0.0, 0.0, 0.0);
        let m0 = collide(&a, &xa, &b, &xf(0.2, 0.999, 0.0), SPEC);
        let m1 = collide(&a, &xa, &b, &xf(0.21, 0.997, 0.002), SPEC);
        assert_eq!(m0.point_count, 2);
        assert_eq!(m1.point_count, 2);
        let mut i0: Vec<u16> = m0.points().iter().map(|p| p.id).collect();
        let mut i1: Vec<u16> = m1.points().iter().map(|p| p.id).collect();
        i0.sort();
        i1.sort();
        assert_eq!(i0, i1);
    }

    #[test]
    fn tilted_box_touches_with_one_corner() {
        let ground = Shape::Polygon(Polygon::make_box(5.0, 0.5));
        let b = boxes(0.5);
        let xa = xf(0.0, 0.0, 0.0);
        // Turned 45°: lowest corner at y = cy - 0.5√2; put it 0.01 deep.
        let h = 0.5 * (2.0 as Real).sqrt();
        let xb = xf(1.0, 0.5 + h - 0.01, PI / 4.0);
        let m = collide(&ground, &xa, &b, &xb, SPEC);
        check_conventions(&m, &xa, &xb);
        assert_eq!(m.point_count, 1);
        assert!(near(m.normal, v(0.0, 1.0), TOL));
        assert!((m.points[0].separation + 0.01).abs() < TOL);
        assert!((m.points[0].point.x - 1.0).abs() < TOL);
    }

    #[test]
    fn separated_corners_use_vertex_normal() {
        let (a, b) = (boxes(0.5), boxes(0.5));
        let xa = xf(0.0, 0.0, 0.0);
        let g = 0.005;
        let xb = xf(1.0 + g, 1.0 + g, 0.0);
        let m = collide(&a, &xa, &b, &xb, SPEC);
        check_conventions(&m, &xa, &xb);
        assert_eq!(m.point_count, 1);
        let d = (2.0 as Real).sqrt() * g;
        assert!((m.points[0].separation - d).abs() < 10.0 * TOL);
        let diag = v(1.0, 1.0).normalize();
        assert!(near(m.normal, diag, 1e-4), "{:?}", m.normal);
        // Ids: A's vertex 2 (top right) against B's vertex 0 (bottom left).
        assert_eq!(m.points[0].id, feature_id(2, 0));
    }

    #[test]
    fn rounded_boxes_include_radius() {
        let a = Shape::Polygon(Polygon::make_rounded_box(0.4, 0.4, 0.1));
        let b = Shape::Polygon(Polygon::make_rounded_box(0.4, 0.4, 0.1));
        let xa = xf(0.0, 0.0, 0.0);
        let xb = xf(0.2, 0.99, 0.0);
        let m = collide(&a, &xa, &b, &xb, SPEC);
        check_conventions(&m, &xa, &xb);
        assert_eq!(m.point_count, 2);
        for p in m.points() {
            assert!((p.separation + 0.01).abs() < TOL);
            assert!((p.point.y - 0.495).abs() < TOL);
        }
        // Corners apart: vertex–vertex with the rounding subtracted.
        let xb = xf(0.81, 0.81, 0.0);
        let m = collide(&a, &xa, &b, &xb, SPEC);
        assert_eq!(m.point_count, 1);
        let d = (2.0 as Real).sqrt() * 0.01 - 0.2;
        assert!(
            (m.points[0].separation - d).abs() < 10.0 * TOL,
            "{}",
            m.points[0].separation
        );
    }

    #[test]
    fn circle_against_polygon_regions() {
        let p = boxes(0.5);
        let c = Shape::Circle(Circle::new(v(0.0, 0.0), 0.25).unwrap());
        let xa = xf(1.0, 2.0, 0.0);
        // Face region, 0.05 deep.
        let xb = xf(1.2, 2.7, 0.0);
        let m = collide(&p, &xa, &c, &xb, SPEC);
        check_conventions(&m, &xa, &xb);
        assert_eq!(m.point_count, 1);
        assert!(near(m.normal, v(0.0, 1.0), TOL));
        assert!((m.points[0].separation + 0.05).abs() < TOL);
        assert!(near(m.points[0].point, v(1.2, 2.475), TOL));
        // Vertex region: centre diagonal from the corner (0.5, 0.5).
        let xb = xf(1.0 + 0.5 + 0.15, 2.0 + 0.5 + 0.15, 0.0);
        let m = collide(&p, &xa, &c, &xb, SPEC);
        let d = (0.045 as Real).sqrt() - 0.25;
        assert_eq!(m.point_count, 1);
        assert!((m.points[0].separation - d).abs() < TOL);
        assert!(near(m.normal, v(1.0, 1.0).normalize(), TOL));
        // Circle first: flipped normal.
        let r = collide(&c, &xb, &p, &xa, SPEC);
        check_conventions(&r, &xb, &xa);
        assert!(near(r.normal, -m.normal, TOL));
        assert!(near(r.points[0].point, m.points[0].point, TOL));
        // Centre inside: face normal of the nearest face.
        let xb = xf(1.4, 2.1, 0.0);
        let m = collide(&p, &xa, &c, &xb, SPEC);
        assert!(near(m.normal, v(1.0, 0.0), TOL));
        assert!((m.points[0].separation + 0.35).abs() < TOL);
        // Far away.
        assert!(collide(&p, &xa, &c, &xf(3.0, 2.0, 0.0), SPEC).is_empty());
    }

    #[test]
    fn circles_including_coincident_centres() {
        let a = Shape::Circle(Circle::new(v(0.0, 0.0), 0.5).unwrap());
        let b = Shape::Circle(Circle::new(v(0.1, 0.0), 0.5).unwrap());
        let xa = xf(0.0, 0.0, 0.0);
        let m = collide(&a, &xa, &b, &xf(0.8, 0.0, 0.0), SPEC);
        check_conventions(&m, &xa, &xf(0.8, 0.0, 0.0));
        assert!((m.points[0].separation + 0.1).abs() < TOL);
        assert!(near(m.normal, v(1.0, 0.0), TOL));
        assert!(near(m.points[0].point, v(0.45, 0.0), TOL));
        let m = collide(&a, &xa, &b, &xf(-0.1, 0.0, 0.0), SPEC);
        assert_eq!(m.point_count, 1);
        assert_eq!(m.normal, v(0.0, 1.0));
        assert!((m.points[0].separation + 1.0).abs() < TOL);
    }

    #[test]
    fn capsule_lying_on_box_has_two_points() {
        let ground = Shape::Polygon(Polygon::make_box(5.0, 0.5));
        let cap = Shape::Capsule(Capsule::new(v(-0.5, 0.0), v(0.5, 0.0), 0.25).unwrap());
        let xa = xf(0.0, 0.0, 0.0);
        let xb = xf(1.0, 0.74, 0.0);
        let m = collide(&ground, &xa, &cap, &xb, SPEC);
        check_conventions(&m, &xa, &xb);
        assert_eq!(m.point_count, 2);
        assert!(near(m.normal, v(0.0, 1.0), TOL));
        for p in m.points() {
            assert!((p.separation + 0.01).abs() < TOL);
        }
        let mut xs: Vec<Real> = m.points().iter().map(|p| p.point.x).collect();
        xs.sort_by(Real::total_cmp);
        assert!((xs[0] - 0.5).abs() < TOL && (xs[1] - 1.5).abs() < TOL);
        // Capsule first, standing on its end cap.
        let xb = xf(1.0, 0.5 + 0.75 - 0.02, PI / 2.0);
        let m = collide(&cap, &xb, &ground, &xa, SPEC);
        check_conventions(&m, &xb, &xa);
        assert_eq!(m.point_count, 1);
        assert!(near(m.normal, v(0.0, -1.0), TOL));
        assert!((m.points[0].separation + 0.02).abs() < TOL);
    }

    #[test]
    fn capsule_capsule_parallel_and_crossed() {
        let c = Shape::Capsule(Capsule::new(v(-1.0, 0.0), v(1.0, 0.0), 0.2).unwrap());
        let xa = xf(0.0, 0.0, 0.0);
        // Parallel, offset along the axis: 2 points over the overlap [0.5, 1].
        let xb = xf(1.5, 0.39, 0.0);
        let m = collide(&c, &xa, &c, &xb, SPEC);
        check_conventions(&m, &xa, &xb);
        assert_eq!(m.point_count, 2);
        assert!(near(m.normal, v(0.0, 1.0), TOL));
        let mut xs: Vec<Real> = m.points().iter().map(|p| p.point.x).collect();
        xs.sort_by(Real::total_cmp);
        assert!(
            (xs[0] - 0.5).abs() < TOL && (xs[1] - 1.0).abs() < TOL,
            "{xs:?}"
        );
        for p in m.points() {
            assert!((p.separation + 0.01).abs() < TOL);
            assert!((p.point.y - 0.195).abs() < TOL);
        }
        // Anti-parallel B gives the same points.
        let m2 = collide(&c, &xa, &c, &xf(1.5, 0.39, PI), SPEC);
        assert_eq!(m2.point_count, 2);
        // Crossed at right angles, 0.05 deep: one point.
        let xb = xf(0.3, 0.35, PI / 2.0 + 0.1);
        let xb = Transform {
            p: v(0.3, 0.35 + 1.0),
            q: xb.q,
        };
        let m = collide(&c, &xa, &c, &xb, SPEC);
        check_conventions(&m, &xa, &xb);
        assert_eq!(m.point_count, 1);
        assert!(m.normal.y > 0.99);
        // Crossing cores: finite, deterministic normal.
        let m = collide(&c, &xa, &c, &xf(0.0, 0.0, PI / 2.0), SPEC);
        assert_eq!(m.point_count, 1);
        assert!(m.normal.is_finite() && (m.normal.length() - 1.0).abs() < TOL);
        assert!((m.points[0].separation + 0.4).abs() < TOL);
    }

    #[test]
    fn segment_against_circle_and_polygon() {
        let s = Shape::Segment(Segment::new(v(-2.0, 0.0), v(2.0, 0.0)).unwrap());
        let c = Shape::Circle(Circle::new(v(0.0, 0.0), 0.5).unwrap());
        let xa = xf(0.0, 0.0, 0.0);
        // Two-sided: from above and from below.
        for y in [0.49, -0.49] {
            let xb = xf(1.0, y, 0.0);
            let m = collide(&s, &xa, &c, &xb, SPEC);
            check_conventions(&m, &xa, &xb);
            assert_eq!(m.point_count, 1);
            assert!(near(m.normal, v(0.0, y.signum()), TOL));
            assert!((m.points[0].separation + 0.01).abs() < TOL);
        }
        // Beyond the end: distance to the end point.
        let xb = xf(2.3, 0.4, 0.0);
        let m = collide(&s, &xa, &c, &xb, SPEC);
        assert!((m.points[0].separation).abs() < TOL);
        assert!(near(m.normal, v(0.6, 0.8), TOL));
        // Box resting on the segment.
        let b = boxes(0.5);
        let xb = xf(0.5, 0.5, 0.0);
        let m = collide(&b, &xb, &s, &xa, SPEC);
        check_conventions(&m, &xb, &xa);
        assert_eq!(m.point_count, 2);
        assert!(near(m.normal, v(0.0, -1.0), TOL));
        // Segment–segment (crossing): one deterministic point.
        let m = collide(&s, &xa, &s, &xf(0.0, 0.0, 1.0), SPEC);
        assert_eq!(m.point_count, 1);
        assert!(m.normal.is_finite());
    }

    fn ground_chain() -> Vec<ChainSegment> {
        // Runs right to left so the front normal points up.
        make_chain(&[v(4.0, 0.0), v(0.0, 0.0), v(-4.0, 0.0)], false).unwrap()
    }

    #[test]
    fn chain_is_one_sided() {
        let chain = ground_chain();
        let s = Shape::ChainSegment(chain[0]);
        assert!(near(chain[0].normal(), v(0.0, 1.0), TOL));
        let xa = xf(0.0, 0.0, 0.0);
        let c = Shape::Circle(Circle::new(v(0.0, 0.0), 0.5).unwrap());
        // From the front: contact, normal up.
        let xb = xf(2.0, 0.49, 0.0);
        let m = collide(&s, &xa, &c, &xb, SPEC);
        check_conventions(&m, &xa, &xb);
        assert_eq!(m.point_count, 1);
        assert!(near(m.normal, v(0.0, 1.0), TOL));
        // From behind: nothing, in both argument orders.
        let xb = xf(2.0, -0.49, 0.0);
        assert!(collide(&s, &xa, &c, &xb, SPEC).is_empty());
        assert!(collide(&c, &xb, &s, &xa, SPEC).is_empty());
        // Boxes and capsules from behind: nothing; from the front: contact.
        let b = boxes(0.5);
        assert!(collide(&s, &xa, &b, &xf(2.0, -0.49, 0.0), SPEC).is_empty());
        assert!(collide(&b, &xf(2.0, -0.49, 0.0), &s, &xa, SPEC).is_empty());
        let m = collide(&b, &xf(2.0, 0.49, 0.0), &s, &xa, SPEC);
        assert_eq!(m.point_count, 2);
        assert!(near(m.normal, v(0.0, -1.0), TOL));
        let cap = Shape::Capsule(Capsule::new(v(-0.5, 0.0), v(0.5, 0.0), 0.25).unwrap());
        assert!(collide(&s, &xa, &cap, &xf(2.0, -0.24, 0.0), SPEC).is_empty());
        assert_eq!(
            collide(&s, &xa, &cap, &xf(2.0, 0.24, 0.0), SPEC).point_count,
            2
        );
    }

    #[test]
    fn chain_shared_vertex_reported_once() {
        let chain = ground_chain();
        let (s0, s1) = (Shape::ChainSegment(chain[0]), Shape::ChainSegment(chain[1]));
        let xa = xf(0.0, 0.0, 0.0);
        let c = Shape::Circle(Circle::new(v(0.0, 0.0), 0.5).unwrap());
        for x in [0.0, 0.1, -0.1] {
            let xb = xf(x, 0.49, 0.0);
            let n = collide(&s0, &xa, &c, &xb, SPEC).point_count
                + collide(&s1, &xa, &c, &xb, SPEC).point_count;
            assert_eq!(n, 1, "x = {x}");
        }
        // Open end: the end vertex is a rounded corner.
        let xb = xf(4.3, 0.4, 0.0);
        let m = collide(&s0, &xa, &c, &xb, SPEC);
        assert_eq!(m.point_count, 1);
        assert!(near(m.normal, v(0.6, 0.8), TOL));
        // Convex corner of a closed square loop (counter-clockwise, outside).
        let sq = make_chain(
            &[v(-1.0, -1.0), v(1.0, -1.0), v(1.0, 1.0), v(-1.0, 1.0)],
            true,
        )
        .unwrap();
        let xb = xf(1.3, 1.3, 0.0);
        let total: usize = sq
            .iter()
            .map(|s| collide(&Shape::ChainSegment(*s), &xa, &c, &xb, SPEC).point_count)
            .sum();
        assert_eq!(total, 1);
    }

    #[test]
    fn box_sliding_over_internal_vertex_does_not_snag() {
        let chain = ground_chain();
        let xa = xf(0.0, 0.0, 0.0);
        let b = boxes(0.5);
        // Box slightly sunk (0.002) with its left face just past the vertex at
        // x = 0: the right segment must not report a horizontal normal.
        for x in [-0.499, -0.5, -0.501, 0.499, 0.5, 0.501, 0.0] {
            let xb = xf(x, 0.498, 0.0);
            let mut points = 0;
            for s in &chain {
                let m = collide(&Shape::ChainSegment(*s), &xa, &b, &xb, SPEC);
                check_conventions(&m, &xa, &xb);
                if m.point_count > 0 {
                    assert!(near(m.normal, v(0.0, 1.0), TOL), "x {x}: {:?}", m.normal);
                    points += m.point_count;
                }
            }
            assert!(points >= 2, "x {x}: {points} points");
        }
    }

    /// A box pressed deep into the concave vertex of a valley (as the
    /// spinner's paddle presses bodies into its loop) turns its own face
    /// normal into the best axis; the segments must still hold it along
    /// their faces (they used to drop it, and it passed through the wall).
    #[test]
    fn chain_holds_a_box_pressed_deep_into_a_concave_vertex() {
        // Right to left, front normals up: a valley with its vertex at 0.
        let chain = make_chain(&[v(4.0, 1.0), v(0.0, 0.0), v(-4.0, 1.0)], false).unwrap();
        let b = boxes(0.35);
        let xa = xf(0.0, 0.0, 0.0);
        for (x, y, angle) in [(0.1, 0.12, 0.6), (-0.15, 0.1, -0.5), (0.0, 0.05, 0.78)] {
            let xb = xf(x, y, angle);
            let mut deepest: Real = 0.0;
            let mut manifolds = 0;
            for s in &chain {
                let m = collide(&Shape::ChainSegment(*s), &xa, &b, &xb, SPEC);
                check_conventions(&m, &xa, &xb);
                if m.point_count > 0 {
                    manifolds += 1;
                    assert!(
                        near(m.normal, s.normal(), TOL),
                        "{:?} vs {:?}",
                        m.normal,
                        s.normal()
                    );
                    for p in m.points() {
                        deepest = deepest.min(p.separation);
                    }
                }
            }
            assert!(
                manifolds >= 1,
                "box at ({x}, {y}, {angle}): no segment holds it"
            );
            assert!(
                deepest < -0.1,
                "box at ({x}, {y}, {angle}): deepest {deepest}"
            );
        }
    }

    #[test]
    fn chain_against_chain_and_segment() {
        let chain = ground_chain();
        let a = Shape::ChainSegment(chain[0]);
        let xa = xf(0.0, 0.0, 0.0);
        // Another ground chain flipped upside down, facing down, just above.
        let other = make_chain(&[v(-1.0, 0.0), v(1.0, 0.0)], false).unwrap();
        let b = Shape::ChainSegment(other[0]);
        let xb = xf(2.0, 0.01, 0.0);
        let m = collide(&a, &xa, &b, &xb, SPEC);
        check_conventions(&m, &xa, &xb);
        assert_eq!(m.point_count, 2);
        assert!(near(m.normal, v(0.0, 1.0), TOL));
        // Facing the same way (B's back to A): nothing.
        assert!(collide(&a, &xa, &b, &xf(2.0, 0.01, PI), SPEC).is_empty());
        let seg = Shape::Segment(Segment::new(v(-1.0, 0.0), v(1.0, 0.0)).unwrap());
        let m = collide(&seg, &xb, &a, &xa, SPEC);
        assert_eq!(m.point_count, 2);
        assert!(near(m.normal, v(0.0, -1.0), TOL));
    }

    #[test]
    fn all_pairs_are_finite_and_consistent() {
        let chain = make_chain(&[v(2.0, -0.2), v(0.0, 0.0), v(-2.0, 0.3)], false).unwrap();
        let shapes = [
            Shape::Circle(Circle::new(v(0.1, 0.0), 0.4).unwrap()),
            Shape::Capsule(Capsule::new(v(-0.4, 0.0), v(0.4, 0.1), 0.2).unwrap()),
            Shape::Polygon(Polygon::make_box(0.4, 0.3)),
            Shape::Polygon(Polygon::make_rounded_box(0.3, 0.2, 0.1)),
            Shape::Polygon(
                Polygon::from_hull(&[v(-0.3, -0.3), v(0.4, -0.2), v(0.1, 0.5)], 0.0).unwrap(),
            ),
            Shape::Segment(Segment::new(v(-0.5, 0.0), v(0.5, 0.0)).unwrap()),
            Shape::ChainSegment(chain[0]),
            Shape::ChainSegment(chain[1]),
        ];
        let mut contacts = 0;
        for a in &shapes {
            for b in &shapes {
                for k in 0..40 {
                    let t = k as Real;
                    let xa = xf(0.1 * (t * 0.7).sin(), 0.0, 0.3 * t);
                    let xb = xf(0.9 * (t * 1.3).cos(), 0.9 * (t * 0.9).sin(), -0.7 * t);
                    let m = collide(a, &xa, b, &xb, SPEC);
                    check_conventions(&m, &xa, &xb);
                    let r = collide(b, &xb, a, &xa, SPEC);
                    check_conventions(&r, &xb, &xa);
                    contacts += m.point_count;
                    // Determinism.
                    assert_eq!(m, collide(a, &xa, b, &xb, SPEC));
                    // Coincident placement never gives NaN.
                    let m = collide(a, &xa, b, &xa, SPEC);
                    check_conventions(&m, &xa, &xa);
                }
            }
        }
        assert!(contacts > 100);
    }

    #[test]
    fn polygon_circle_separation_matches_true_distance() {
        let a = Shape::Polygon(Polygon::make_box(0.5, 0.5));
        let r = 0.3;
        let c = Shape::Circle(Circle::new(v(0.0, 0.0), r).unwrap());
        let xa = xf(0.2, -0.1, 0.4);
        let mut hits = 0;
        for k in 0..32 {
            let ang = k as Real * PI / 16.0;
            let p = xa.p + 0.95 * v(ang.cos(), ang.sin());
            // Brute force: distance from the centre to the box in its frame.
            let local = xa.apply_inv(p);
            let d = (local - local.clamp(v(-0.5, -0.5), v(0.5, 0.5))).length();
            let truth = d - r;
            let m = collide(&a, &xa, &c, &xf(p.x, p.y, 0.0), SPEC);
            if truth < SPEC - 1e-4 {
                assert_eq!(m.point_count, 1, "k {k}");
                let s = m.points[0].separation;
                assert!((s - truth).abs() < 10.0 * TOL, "k {k}: {s} vs {truth}");
                hits += 1;
            } else if truth > SPEC + 1e-4 {
                assert!(m.is_empty(), "k {k}");
            }
        }
        assert!(hits >= 8, "{hits}");
    }
}
