//! Distance, closest points, overlap and shape casts between convex shapes,
//! by GJK on their cores.
//!
//! Every shape is a [`ShapeProxy`]: a convex hull of at most
//! [`MAX_POLYGON_VERTICES`] core points, grown by a radius (a circle is one
//! point, a capsule or segment two, a polygon its vertices).
//!
//! | function          | answer                                                      |
//! |-------------------|-------------------------------------------------------------|
//! | [`shape_distance`] | distance between the surfaces, closest points, unit normal A → B |
//! | [`shapes_overlap`] | true when the shapes touch or overlap                      |
//! | [`shape_cast`]     | first contact of B moving along a translation: fraction, point, normal |
//!
//! GJK works on the Minkowski difference of the cores, with a simplex of up
//! to three points; it stops when the simplex contains the origin (the cores
//! overlap), when a support point repeats, or after [`GJK_MAX_ITERATIONS`].
//! The shape cast is conservative advancement: the distance between two
//! convex sets under a translation is a convex function of the fraction, so
//! a Newton step `t += gap / closing speed` never passes the first contact.
//!
//! ```
//! use janus2d_core::geometry::{Circle, Polygon, Shape, ShapeProxy, shape_distance};
//! use janus2d_core::math::{Transform, Vec2};
//! let ball = ShapeProxy::from_shape(&Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap()));
//! let crate_ = ShapeProxy::from_shape(&Shape::Polygon(Polygon::make_box(1.0, 1.0)));
//! let out = shape_distance(
//!     &ball, &Transform::new(Vec2::new(-3.0, 0.0), 0.0),
//!     &crate_, &Transform::IDENTITY,
//! );
//! assert!((out.distance - 1.5).abs() < 1e-5);
//! assert!((out.normal - Vec2::X).length() < 1e-5);
//! ```

use super::shapes::{GeometryError, LINEAR_SLOP, MAX_POLYGON_VERTICES, Shape};
use crate::geometry::CastHit;
use crate::math::{EPSILON, Real, Transform, Vec2, cross, vec_is_finite};

/// Iteration cap of the GJK loop (a count; usual value 20).
pub const GJK_MAX_ITERATIONS: usize = 20;

/// Iteration cap of the shape cast's conservative advancement (a count; usual 30).
pub const CAST_MAX_ITERATIONS: usize = 30;

/// How close (m) the surfaces are when [`shape_cast`] reports a contact
/// (usual 0.00025 = [`LINEAR_SLOP`] / 20).
pub const CAST_TOLERANCE: Real = 0.05 * LINEAR_SLOP;

/// A convex point set grown by a radius: the shape GJK sees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeProxy {
    /// Core points (body frame), m; entries at `count..` are unused.
    pub points: [Vec2; MAX_POLYGON_VERTICES],
    /// Number of points in use (1 to [`MAX_POLYGON_VERTICES`]).
    pub count: usize,
    /// Radius around the core, m (≥ 0).
    pub radius: Real,
}

impl ShapeProxy {
    /// A proxy from core points and a radius. Errors: no point or more than
    /// [`MAX_POLYGON_VERTICES`], non-finite input, negative radius.
    pub fn new(points: &[Vec2], radius: Real) -> Result<ShapeProxy, GeometryError> {
        if points.is_empty() {
            return Err(GeometryError::TooFewPoints {
                found: 0,
                needed: 1,
            });
        }
        if points.len() > MAX_POLYGON_VERTICES {
            return Err(GeometryError::TooManyVertices {
                count: points.len(),
            });
        }
        if !radius.is_finite() || points.iter().any(|p| !vec_is_finite(*p)) {
            return Err(GeometryError::NonFinite);
        }
        if radius < 0.0 {
            return Err(GeometryError::NegativeRadius);
        }
        let mut proxy = ShapeProxy {
            points: [Vec2::ZERO; MAX_POLYGON_VERTICES],
            count: points.len(),
            radius,
        };
        proxy.points[..points.len()].copy_from_slice(points);
        Ok(proxy)
    }

    /// A single point (radius 0).
    pub fn point(p: Vec2) -> ShapeProxy {
        let mut points = [Vec2::ZERO; MAX_POLYGON_VERTICES];
        points[0] = p;
        ShapeProxy {
            points,
            count: 1,
            radius: 0.0,
        }
    }

    /// The proxy of a shape (a chain segment is its segment: two-sided).
    pub fn from_shape(shape: &Shape) -> ShapeProxy {
        let mut points = [Vec2::ZERO; MAX_POLYGON_VERTICES];
        let (count, radius) = match shape {
            Shape::Circle(c) => {
                points[0] = c.center;
                (1, c.radius)
            }
            Shape::Capsule(c) => {
                points[0] = c.center1;
                points[1] = c.center2;
                (2, c.radius)
            }
            Shape::Polygon(p) => {
                // An unvalidated polygon's count is clamped, never trusted.
                let n = p.count.clamp(1, MAX_POLYGON_VERTICES);
                points[..n].copy_from_slice(&p.vertices[..n]);
                (n, p.radius)
            }
            Shape::Segment(s) => {
                points[0] = s.point1;
                points[1] = s.point2;
                (2, 0.0)
            }
            Shape::ChainSegment(c) => {
                points[0] = c.segment.point1;
                points[1] = c.segment.point2;
                (2, 0.0)
            }
        };
        ShapeProxy {
            points,
            count,
            radius,
        }
    }

    /// The proxy of an axis-aligned box given by its corners.
    pub fn from_box(lower: Vec2, upper: Vec2) -> ShapeProxy {
        let mut points = [Vec2::ZERO; MAX_POLYGON_VERTICES];
        points[0] = lower;
        points[1] = Vec2::new(upper.x, lower.y);
        points[2] = upper;
        points[3] = Vec2::new(lower.x, upper.y);
        ShapeProxy {
            points,
            count: 4,
            radius: 0.0,
        }
    }

    /// The points placed by `xf`.
    fn placed(&self, xf: &Transform) -> [Vec2; MAX_POLYGON_VERTICES] {
        let mut out = [Vec2::ZERO; MAX_POLYGON_VERTICES];
        for i in 0..self.count {
            out[i] = xf.apply(self.points[i]);
        }
        out
    }
}

/// The index of the point of `pts` furthest along `d`.
#[inline]
fn support(pts: &[Vec2], d: Vec2) -> usize {
    let mut best = 0;
    let mut best_value = pts[0].dot(d);
    for (i, p) in pts.iter().enumerate().skip(1) {
        let value = p.dot(d);
        if value > best_value {
            best = i;
            best_value = value;
        }
    }
    best
}

/// Distance between two shapes and their closest points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistanceOutput {
    /// Closest point on A's surface, world, m.
    pub point_a: Vec2,
    /// Closest point on B's surface, world, m.
    pub point_b: Vec2,
    /// Unit normal from A to B; zero when the cores overlap.
    pub normal: Vec2,
    /// Distance between the surfaces, m (0 when they touch or overlap).
    pub distance: Real,
    /// GJK iterations used.
    pub iterations: usize,
}

#[derive(Clone, Copy, Debug, Default)]
struct SimplexVertex {
    wa: Vec2,
    wb: Vec2,
    w: Vec2,
    a: Real,
    ia: usize,
    ib: usize,
}

/// Closest points of the two cores (no radius): `(point_a, point_b,
/// overlapping, iterations)`.
fn gjk(pa: &[Vec2], pb: &[Vec2]) -> (Vec2, Vec2, bool, usize) {
    let vertex = |ia: usize, ib: usize| SimplexVertex {
        wa: pa[ia],
        wb: pb[ib],
        w: pb[ib] - pa[ia],
        a: 1.0,
        ia,
        ib,
    };
    let mut s = [
        vertex(0, 0),
        SimplexVertex::default(),
        SimplexVertex::default(),
    ];
    let mut n = 1;
    let mut iterations = 0;
    let mut overlap = false;
    while iterations < GJK_MAX_ITERATIONS {
        let saved: [(usize, usize); 3] =
            [(s[0].ia, s[0].ib), (s[1].ia, s[1].ib), (s[2].ia, s[2].ib)];
        let saved_n = n;
        match n {
            2 => solve2(&mut s, &mut n),
            3 => solve3(&mut s, &mut n),
            _ => {}
        }
        if n == 3 {
            overlap = true;
            break;
        }
        let v = closest(&s, n);
        let scale = s[..n]
            .iter()
            .map(|x| x.w.length_squared())
            .fold(1.0, Real::max);
        if v.length_squared() <= 100.0 * EPSILON * EPSILON * scale {
            overlap = true;
            break;
        }
        let d = -v;
        let ia = support(pa, -d);
        let ib = support(pb, d);
        iterations += 1;
        if saved[..saved_n].contains(&(ia, ib)) {
            break;
        }
        let nv = vertex(ia, ib);
        // No progress towards the origin: v is the closest point.
        if nv.w.dot(d) - v.dot(d) <= 10.0 * EPSILON * v.length_squared() {
            break;
        }
        s[n] = nv;
        n += 1;
    }
    let mut a = Vec2::ZERO;
    let mut b = Vec2::ZERO;
    for x in &s[..n] {
        a += x.a * x.wa;
        b += x.a * x.wb;
    }
    if overlap {
        let m = 0.5 * (a + b);
        (m, m, true, iterations)
    } else {
        (a, b, false, iterations)
    }
}

fn closest(s: &[SimplexVertex; 3], n: usize) -> Vec2 {
    s[..n].iter().fold(Vec2::ZERO, |acc, x| acc + x.a * x.w)
}

/// Closest point of segment w1–w2 to the origin, in barycentric form.
fn solve2(s: &mut [SimplexVertex; 3], n: &mut usize) {
    let (w1, w2) = (s[0].w, s[1].w);
    let e12 = w2 - w1;
    let d12_2 = -w1.dot(e12);
    if d12_2 <= 0.0 {
        s[0].a = 1.0;
        *n = 1;
        return;
    }
    let d12_1 = w2.dot(e12);
    if d12_1 <= 0.0 {
        s[0] = s[1];
        s[0].a = 1.0;
        *n = 1;
        return;
    }
    let inv = 1.0 / (d12_1 + d12_2);
    s[0].a = d12_1 * inv;
    s[1].a = d12_2 * inv;
    *n = 2;
}

/// Closest point of triangle w1–w2–w3 to the origin (Voronoi regions).
fn solve3(s: &mut [SimplexVertex; 3], n: &mut usize) {
    let (w1, w2, w3) = (s[0].w, s[1].w, s[2].w);
    let e12 = w2 - w1;
    let d12_1 = w2.dot(e12);
    let d12_2 = -w1.dot(e12);
    let e13 = w3 - w1;
    let d13_1 = w3.dot(e13);
    let d13_2 = -w1.dot(e13);
    let e23 = w3 - w2;
    let d23_1 = w3.dot(e23);
    let d23_2 = -w2.dot(e23);
    let n123 = cross(e12, e13);
    let d123_1 = n123 * cross(w2, w3);
    let d123_2 = n123 * cross(w3, w1);
    let d123_3 = n123 * cross(w1, w2);

    if d12_2 <= 0.0 && d13_2 <= 0.0 {
        s[0].a = 1.0;
        *n = 1;
    } else if d12_1 > 0.0 && d12_2 > 0.0 && d123_3 <= 0.0 {
        let inv = 1.0 / (d12_1 + d12_2);
        s[0].a = d12_1 * inv;
        s[1].a = d12_2 * inv;
        *n = 2;
    } else if d13_1 > 0.0 && d13_2 > 0.0 && d123_2 <= 0.0 {
        let inv = 1.0 / (d13_1 + d13_2);
        s[0].a = d13_1 * inv;
        s[2].a = d13_2 * inv;
        s[1] = s[2];
        *n = 2;
    } else if d12_1 <= 0.0 && d23_2 <= 0.0 {
        s[0] = s[1];
        s[0].a = 1.0;
        *n = 1;
    } else if d13_1 <= 0.0 && d23_1 <= 0.0 {
        s[0] = s[2];
        s[0].a = 1.0;
        *n = 1;
    } else if d23_1 > 0.0 && d23_2 > 0.0 && d123_1 <= 0.0 {
        let inv = 1.0 / (d23_1 + d23_2);
        s[1].a = d23_1 * inv;
        s[2].a = d23_2 * inv;
        s[0] = s[2];
        *n = 2;
    } else {
        let inv = 1.0 / (d123_1 + d123_2 + d123_3);
        s[0].a = d123_1 * inv;
        s[1].a = d123_2 * inv;
        s[2].a = d123_3 * inv;
        *n = 3;
    }
}

/// Distance between the core point sets (radius ignored).
pub(crate) fn core_distance(
    a: &ShapeProxy,
    xf_a: &Transform,
    b: &ShapeProxy,
    xf_b: &Transform,
) -> DistanceOutput {
    let pa = a.placed(xf_a);
    let pb = b.placed(xf_b);
    let (point_a, point_b, overlap, iterations) = gjk(&pa[..a.count], &pb[..b.count]);
    let delta = point_b - point_a;
    let distance = if overlap { 0.0 } else { delta.length() };
    let normal = if distance > EPSILON {
        delta / distance
    } else {
        Vec2::ZERO
    };
    DistanceOutput {
        point_a,
        point_b,
        normal,
        distance,
        iterations,
    }
}

/// Distance between the surfaces of A (placed by `xf_a`) and B (placed by
/// `xf_b`), their closest points and the unit normal from A to B. When the
/// shapes touch or overlap the distance is 0; the two points are then one
/// point (midway between the cores' closest points, or inside both when the
/// cores overlap) and the normal is zero if the cores overlap.
pub fn shape_distance(
    a: &ShapeProxy,
    xf_a: &Transform,
    b: &ShapeProxy,
    xf_b: &Transform,
) -> DistanceOutput {
    let mut out = core_distance(a, xf_a, b, xf_b);
    let radii = a.radius + b.radius;
    if out.distance > radii && out.normal != Vec2::ZERO {
        out.point_a += a.radius * out.normal;
        out.point_b -= b.radius * out.normal;
        out.distance -= radii;
    } else {
        // Touching or overlapping: one point between the two surfaces.
        let p = if out.normal != Vec2::ZERO {
            let on_a = out.point_a + a.radius * out.normal;
            let on_b = out.point_b - b.radius * out.normal;
            0.5 * (on_a + on_b)
        } else {
            out.point_a
        };
        out.point_a = p;
        out.point_b = p;
        out.distance = 0.0;
    }
    out
}

/// True when the two shapes touch or overlap.
pub fn shapes_overlap(a: &ShapeProxy, xf_a: &Transform, b: &ShapeProxy, xf_b: &Transform) -> bool {
    let out = core_distance(a, xf_a, b, xf_b);
    out.distance <= a.radius + b.radius
}

/// The first contact of B (placed by `xf_b`) moving along `translation_b`
/// against A (placed by `xf_a`, fixed), for fractions in `[0, max_fraction]`.
///
/// The hit's point is on A's surface, its normal is A's unit surface normal
/// there (from A towards B) and its fraction is where the surfaces come
/// within [`CAST_TOLERANCE`]. Shapes that already overlap give fraction 0
/// (normal from A to B, or against the translation when the cores overlap).
/// A zero translation hits only when the shapes overlap.
pub fn shape_cast(
    a: &ShapeProxy,
    xf_a: &Transform,
    b: &ShapeProxy,
    xf_b: &Transform,
    translation_b: Vec2,
    max_fraction: Real,
) -> Option<CastHit> {
    let radii = a.radius + b.radius;
    let mut t: Real = 0.0;
    // The translation's length and direction without overflow: `|d|²`
    // overflows beyond ~1.8e19 in f32 (a cast then missed everything).
    let (length, direction) = length_and_direction(translation_b);
    let mut last_normal = -direction;
    for iteration in 0..CAST_MAX_ITERATIONS {
        let xf = Transform {
            p: xf_b.p + t * translation_b,
            q: xf_b.q,
        };
        let out = core_distance(a, xf_a, b, &xf);
        let gap = out.distance - radii;
        if out.normal != Vec2::ZERO {
            last_normal = out.normal;
        }
        if gap < CAST_TOLERANCE {
            if iteration == 0 && gap < 0.0 {
                t = 0.0;
            }
            let point = if out.normal != Vec2::ZERO {
                out.point_a + a.radius * out.normal
            } else {
                out.point_a
            };
            return Some(CastHit {
                point,
                normal: last_normal,
                fraction: t,
            });
        }
        let closing = -translation_b.dot(out.normal);
        if closing <= EPSILON * length {
            return None; // not approaching along the separating axis: never meets
        }
        // Aim a little short of touching so that the loop ends on the near side.
        t += (gap - 0.5 * CAST_TOLERANCE) / closing;
        if t > max_fraction {
            return None;
        }
    }
    None
}

/// `(|v|, v / |v|)` (zero direction for a zero `v`), `|v|` computed as
/// `m |v / m|` with `m = max(|x|, |y|)` when `|v|²` overflows (the
/// length may still be ∞ beyond `Real::MAX`, the direction is unit).
fn length_and_direction(v: Vec2) -> (Real, Vec2) {
    let length = v.length();
    if length.is_finite() {
        return (length, v.normalize_or_zero());
    }
    let m = v.abs().max_element();
    if !m.is_finite() || m == 0.0 {
        return (length, Vec2::ZERO);
    }
    let unit = v / m;
    let unit_length = unit.length();
    (m * unit_length, unit / unit_length)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Capsule, Circle, Polygon, Segment};

    fn v(x: Real, y: Real) -> Vec2 {
        Vec2::new(x, y)
    }

    fn proxy(s: Shape) -> ShapeProxy {
        ShapeProxy::from_shape(&s)
    }

    fn at(x: Real, y: Real, angle: Real) -> Transform {
        Transform::new(v(x, y), angle)
    }

    #[test]
    fn distance_circle_to_box_face_and_corner() {
        let ball = proxy(Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap()));
        let b = proxy(Shape::Polygon(Polygon::make_box(1.0, 1.0)));
        // Face: ball at (0, 4) above a unit box: gap 4 − 1 − 0.5.
        let out = shape_distance(&b, &Transform::IDENTITY, &ball, &at(0.3, 4.0, 0.0));
        assert!((out.distance - 2.5).abs() < 1e-5, "{out:?}");
        assert!((out.point_a - v(0.3, 1.0)).length() < 1e-5);
        assert!((out.point_b - v(0.3, 3.5)).length() < 1e-5);
        assert!((out.normal - v(0.0, 1.0)).length() < 1e-5);
        // Corner: ball at (4, 5): corner (1, 1), distance 5 − 0.5.
        let out = shape_distance(&b, &Transform::IDENTITY, &ball, &at(4.0, 5.0, 0.0));
        assert!((out.distance - 4.5).abs() < 1e-5, "{out:?}");
        assert!((out.point_a - v(1.0, 1.0)).length() < 1e-5);
        assert!((out.normal - v(0.6, 0.8)).length() < 1e-5);
    }

    #[test]
    fn distance_between_rotated_boxes_and_capsules() {
        // A box turned 45° has its corner at x = √2; the other box's face at 3.
        let a = proxy(Shape::Polygon(Polygon::make_box(1.0, 1.0)));
        let d = shape_distance(
            &a,
            &at(0.0, 0.0, crate::math::PI / 4.0),
            &a,
            &at(4.0, 0.1, 0.0),
        );
        let expect = 3.0 - (2.0 as Real).sqrt();
        assert!((d.distance - expect).abs() < 1e-5, "{d:?}");
        assert!((d.point_a - v((2.0 as Real).sqrt(), 0.0)).length() < 1e-5);
        // Parallel capsules 2 m apart with radius 0.25 each.
        let c = proxy(Shape::Capsule(
            Capsule::new(v(-1.0, 0.0), v(1.0, 0.0), 0.25).unwrap(),
        ));
        let d = shape_distance(&c, &Transform::IDENTITY, &c, &at(0.5, 2.0, 0.0));
        assert!((d.distance - 1.5).abs() < 1e-5);
        assert!((d.normal - v(0.0, 1.0)).length() < 1e-5);
        // Crossed segments overlap.
        let s = proxy(Shape::Segment(
            Segment::new(v(-1.0, 0.0), v(1.0, 0.0)).unwrap(),
        ));
        let d = shape_distance(&s, &Transform::IDENTITY, &s, &at(0.0, 0.0, 1.0));
        assert_eq!(d.distance, 0.0);
        assert!(shapes_overlap(
            &s,
            &Transform::IDENTITY,
            &s,
            &at(0.0, 0.0, 1.0)
        ));
    }

    #[test]
    fn overlap_is_exact_near_a_rounded_surface() {
        let ball = proxy(Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap()));
        let p = ShapeProxy::point(v(0.0, 0.0));
        assert!(shapes_overlap(
            &ball,
            &Transform::IDENTITY,
            &p,
            &at(0.49, 0.0, 0.0)
        ));
        assert!(!shapes_overlap(
            &ball,
            &Transform::IDENTITY,
            &p,
            &at(0.51, 0.0, 0.0)
        ));
        // A box whose corner is 1 cm off the ball's surface (diagonally).
        let k = 0.51 / (2.0 as Real).sqrt();
        let bx = ShapeProxy::from_box(v(k, k), v(k + 1.0, k + 1.0));
        assert!(!shapes_overlap(
            &ball,
            &Transform::IDENTITY,
            &bx,
            &Transform::IDENTITY
        ));
    }

    #[test]
    fn shape_cast_circle_onto_box_face() {
        let ball = proxy(Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap()));
        let b = proxy(Shape::Polygon(Polygon::make_box(1.0, 1.0)));
        // Box face at x = 5; the ball's centre touches at x = 4.5.
        let hit = shape_cast(
            &b,
            &at(6.0, 0.0, 0.0),
            &ball,
            &Transform::IDENTITY,
            v(10.0, 0.0),
            1.0,
        )
        .unwrap();
        assert!((hit.fraction - 0.45).abs() < 1e-4, "{hit:?}");
        assert!((hit.point - v(5.0, 0.0)).length() < 1e-3);
        assert!((hit.normal - v(-1.0, 0.0)).length() < 1e-4);
        // Too short a translation: no hit; moving away: no hit.
        assert!(
            shape_cast(
                &b,
                &at(6.0, 0.0, 0.0),
                &ball,
                &Transform::IDENTITY,
                v(4.0, 0.0),
                1.0
            )
            .is_none()
        );
        assert!(
            shape_cast(
                &b,
                &at(6.0, 0.0, 0.0),
                &ball,
                &Transform::IDENTITY,
                v(-4.0, 0.0),
                1.0
            )
            .is_none()
        );
    }

    #[test]
    fn shape_cast_circle_onto_circle_and_initial_overlap() {
        // Two unit-radius discs, the moving one offset by 1 in y: contact when
        // the centres are 2 apart, at x = −√3.
        let c = proxy(Shape::Circle(Circle::new(Vec2::ZERO, 1.0).unwrap()));
        let hit = shape_cast(
            &c,
            &Transform::IDENTITY,
            &c,
            &at(-5.0, 1.0, 0.0),
            v(10.0, 0.0),
            1.0,
        )
        .unwrap();
        let expect = (5.0 - (3.0 as Real).sqrt()) / 10.0;
        assert!((hit.fraction - expect).abs() < 1e-4, "{hit:?}");
        assert!((hit.normal - v(-(3.0 as Real).sqrt() / 2.0, 0.5)).length() < 1e-3);
        // Already overlapping: fraction 0.
        let hit = shape_cast(
            &c,
            &Transform::IDENTITY,
            &c,
            &at(0.5, 0.0, 0.0),
            v(1.0, 0.0),
            1.0,
        )
        .unwrap();
        assert_eq!(hit.fraction, 0.0);
    }

    #[test]
    fn gjk_matches_brute_force_on_random_polygons() {
        use crate::geometry::ray::point_segment_distance_sq;
        let mut seed: u64 = 5;
        let mut unit = move || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((seed >> 40) as Real) / ((1u64 << 24) as Real)
        };
        let mut separated = 0;
        for _ in 0..500 {
            let poly = |unit: &mut dyn FnMut() -> Real| {
                let pts: Vec<Vec2> = (0..6)
                    .map(|_| v(2.0 * unit() - 1.0, 2.0 * unit() - 1.0))
                    .collect();
                Polygon::from_hull(&pts, 0.0).ok()
            };
            let (Some(pa), Some(pb)) = (poly(&mut unit), poly(&mut unit)) else {
                continue;
            };
            let xa = at(3.0 * unit(), 3.0 * unit(), 6.0 * unit());
            let xb = at(3.0 * unit(), 3.0 * unit(), 6.0 * unit());
            let wa: Vec<Vec2> = pa.vertices[..pa.count]
                .iter()
                .map(|p| xa.apply(*p))
                .collect();
            let wb: Vec<Vec2> = pb.vertices[..pb.count]
                .iter()
                .map(|p| xb.apply(*p))
                .collect();
            // SAT over every edge normal: separated when one axis splits them.
            let split = |u: &[Vec2], w: &[Vec2]| {
                (0..u.len()).any(|i| {
                    let e = u[(i + 1) % u.len()] - u[i];
                    let n = Vec2::new(e.y, -e.x);
                    let lim = u.iter().map(|p| p.dot(n)).fold(Real::MIN, Real::max);
                    w.iter().all(|p| p.dot(n) > lim)
                })
            };
            let apart = split(&wa, &wb) || split(&wb, &wa);
            let brute = |u: &[Vec2], w: &[Vec2]| {
                u.iter()
                    .flat_map(|p| (0..w.len()).map(move |i| (p, i)))
                    .map(|(p, i)| point_segment_distance_sq(*p, w[i], w[(i + 1) % w.len()]))
                    .fold(Real::MAX, Real::min)
                    .sqrt()
            };
            let out = shape_distance(
                &proxy(Shape::Polygon(pa)),
                &xa,
                &proxy(Shape::Polygon(pb)),
                &xb,
            );
            if apart {
                separated += 1;
                let want = brute(&wa, &wb).min(brute(&wb, &wa));
                assert!(
                    (out.distance - want).abs() < 1e-4,
                    "{} vs {want}",
                    out.distance
                );
                assert!(((out.point_b - out.point_a).length() - want).abs() < 1e-4);
            } else {
                assert_eq!(out.distance, 0.0);
            }
        }
        assert!(separated > 50, "only {separated} separated pairs");
    }

    #[test]
    fn ray_hits_agree_with_gjk_point_distance() {
        use crate::geometry::RayInput;
        let mut seed: u64 = 21;
        let mut unit = move || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((seed >> 40) as Real) / ((1u64 << 24) as Real)
        };
        let shapes = [
            Shape::Circle(Circle::new(v(0.3, -0.2), 0.7).unwrap()),
            Shape::Capsule(Capsule::new(v(-0.6, 0.0), v(0.5, 0.4), 0.3).unwrap()),
            Shape::Polygon(Polygon::make_offset_box(0.8, 0.4, v(0.1, 0.2), 0.5)),
            Shape::Polygon(Polygon::make_rounded_box(0.5, 0.3, 0.25)),
        ];
        let mut hits = 0;
        for k in 0..2000 {
            let shape = &shapes[k % shapes.len()];
            let xf = at(unit() - 0.5, unit() - 0.5, 6.0 * unit());
            let origin = v(6.0 * unit() - 3.0, 6.0 * unit() - 3.0);
            let d = v(6.0 * unit() - 3.0, 6.0 * unit() - 3.0);
            let p = proxy(*shape);
            let gap = |x: Vec2| {
                shape_distance(&p, &xf, &ShapeProxy::point(x), &Transform::IDENTITY).distance
            };
            let inside =
                |x: Vec2| shapes_overlap(&p, &xf, &ShapeProxy::point(x), &Transform::IDENTITY);
            if inside(origin) {
                assert!(shape.ray_cast(&xf, &RayInput::new(origin, d)).is_none());
                continue;
            }
            match shape.ray_cast(&xf, &RayInput::new(origin, d)) {
                Some(h) => {
                    hits += 1;
                    assert!(
                        gap(h.point) < 1e-4,
                        "{k}: hit {h:?} is {} off",
                        gap(h.point)
                    );
                    let before = origin + (h.fraction - 1e-3 / d.length()).max(0.0) * d;
                    assert!(h.fraction == 0.0 || !inside(before), "{k}: entered earlier");
                    assert!((h.normal.length() - 1.0).abs() < 1e-5);
                    assert!(h.normal.dot(d) <= 0.0, "{k}: normal faces away");
                }
                None => {
                    for i in 0..=100 {
                        let x = origin + (i as Real / 100.0) * d;
                        assert!(!inside(x), "{k}: missed a point inside");
                    }
                }
            }
        }
        assert!(hits > 100, "only {hits} hits");
    }

    #[test]
    fn proxy_constructor_validates() {
        assert!(ShapeProxy::new(&[], 0.0).is_err());
        assert!(ShapeProxy::new(&[v(0.0, 0.0)], -1.0).is_err());
        assert!(ShapeProxy::new(&[v(Real::NAN, 0.0)], 0.0).is_err());
        assert_eq!(
            ShapeProxy::new(&[v(1.0, 0.0), v(2.0, 0.0)], 0.1)
                .unwrap()
                .count,
            2
        );
    }
}
