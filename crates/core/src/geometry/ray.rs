//! Ray casts against single shapes: where a ray `origin + s · translation`,
//! `s ∈ [0, max_fraction]`, first enters a shape.
//!
//! | shape          | rule                                                        |
//! |----------------|-------------------------------------------------------------|
//! | circle         | the smaller root of the quadratic                           |
//! | capsule        | the two end discs and the two offset sides                  |
//! | polygon        | slab clipping against the edge half-planes (sharp)          |
//! | rounded polygon| the offset edges and the vertex discs                       |
//! | segment        | two-sided: the normal faces the ray's origin                |
//! | chain segment  | one-sided: only from the front (see [`ChainSegment`])       |
//!
//! A ray whose origin is inside a solid shape does not hit it (as Box2D):
//! use a point overlap to find what contains a point. A zero translation
//! hits nothing. The normal is the unit outward surface normal at the hit
//! point, facing the ray.
//!
//! ```
//! use janus2d_core::geometry::{Circle, RayInput, Shape};
//! use janus2d_core::math::{Transform, Vec2};
//! let ball = Shape::Circle(Circle::new(Vec2::ZERO, 1.0).unwrap());
//! let ray = RayInput::new(Vec2::new(-3.0, 0.0), Vec2::new(4.0, 0.0));
//! let hit = ball.ray_cast(&Transform::IDENTITY, &ray).unwrap();
//! assert!((hit.fraction - 0.5).abs() < 1e-6);
//! assert!((hit.point - Vec2::new(-1.0, 0.0)).length() < 1e-6);
//! assert!((hit.normal - Vec2::new(-1.0, 0.0)).length() < 1e-6);
//! ```

use super::shapes::{ChainSegment, MAX_POLYGON_VERTICES, Polygon, Shape, right_perp};
use crate::math::{EPSILON, Real, Transform, Vec2};

/// A ray: the points `origin + s · translation` for `s` in `[0, max_fraction]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayInput {
    /// Start point, m.
    pub origin: Vec2,
    /// Displacement from the start to the end of the ray at fraction 1, m.
    pub translation: Vec2,
    /// Largest fraction of `translation` tested (usual 1).
    pub max_fraction: Real,
}

impl RayInput {
    /// A ray over the whole translation (`max_fraction = 1`).
    pub fn new(origin: Vec2, translation: Vec2) -> Self {
        RayInput {
            origin,
            translation,
            max_fraction: 1.0,
        }
    }
}

/// Where a ray or a moving shape first meets a shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CastHit {
    /// The hit point on the surface, m.
    pub point: Vec2,
    /// Unit surface normal at the hit point, facing the caster.
    pub normal: Vec2,
    /// Fraction of the translation travelled at the hit (in `[0, max_fraction]`).
    pub fraction: Real,
}

impl Shape {
    /// The first point where `ray` (in world space) enters the shape placed
    /// by `xf`, or `None`. See the [module docs](self) for the rules.
    pub fn ray_cast(&self, xf: &Transform, ray: &RayInput) -> Option<CastHit> {
        let local = RayInput {
            origin: xf.apply_inv(ray.origin),
            translation: xf.q.inv_rotate(ray.translation),
            max_fraction: ray.max_fraction,
        };
        let hit = match self {
            Shape::Circle(c) => ray_disc(&local, c.center, c.radius),
            Shape::Capsule(c) => ray_rounded_segment(&local, c.center1, c.center2, c.radius),
            Shape::Polygon(p) => ray_polygon(&local, p),
            Shape::Segment(s) => ray_segment(&local, s.point1, s.point2, false),
            Shape::ChainSegment(c) => ray_chain_segment(&local, c),
        }?;
        Some(CastHit {
            point: xf.apply(hit.point),
            normal: xf.q.rotate(hit.normal),
            fraction: hit.fraction,
        })
    }
}

/// True when the ray has a direction and a usable range.
#[inline]
fn usable(ray: &RayInput) -> bool {
    ray.translation.length_squared() > 0.0 && ray.max_fraction >= 0.0
}

/// Ray against the disc of centre `c` and radius `r` (`r > 0`).
///
/// The root is taken from `|d|² s² + 2 (m·d) s + |m|² − r² = 0` directly
/// when those products are finite; when they overflow (a translation or
/// an origin beyond ~1e19 m in `f32`) the same root is found in scaled
/// units (a unit direction, the offset and radius over their largest), so
/// every hit is finite.
pub fn ray_disc(ray: &RayInput, c: Vec2, r: Real) -> Option<CastHit> {
    if !usable(ray) {
        return None;
    }
    let d = ray.translation;
    let m = ray.origin - c;
    let cc = m.length_squared() - r * r;
    let dd = d.length_squared();
    let b = m.dot(d);
    let disc = b * b - dd * cc;
    if !(cc.is_finite() && dd.is_finite() && disc.is_finite()) {
        return ray_disc_scaled(ray, c, r);
    }
    if cc <= 0.0 {
        return None; // origin inside (or on) the disc
    }
    if b >= 0.0 {
        return None; // moving away
    }
    if disc < 0.0 {
        return None;
    }
    // Smaller root of dd s² + 2 b s + cc = 0, in the cancellation-free form.
    let s = cc / (-b + disc.sqrt());
    if s < 0.0 || s > ray.max_fraction {
        return None;
    }
    let point = ray.origin + s * d;
    let normal = (point - c).try_normalize().unwrap_or(-d.normalize());
    Some(CastHit {
        point,
        normal,
        fraction: s,
    })
}

/// [`ray_disc`] for magnitudes whose squares overflow: the translation as
/// a unit direction `u` and a length `L`, the offset `m` and the radius in
/// units of `w = max(|m|∞, r)`; the root is the distance `t` along `u` in
/// units of `w`, and the fraction `t w / L`.
fn ray_disc_scaled(ray: &RayInput, c: Vec2, r: Real) -> Option<CastHit> {
    let d = ray.translation;
    let m = ray.origin - c;
    let d_max = d.abs().max_element();
    let w = m.abs().max_element().max(r);
    if !(m.is_finite() && d_max > 0.0 && w > 0.0 && w.is_finite()) {
        return None;
    }
    let d1 = d / d_max;
    let d1_len = d1.length(); // in [1, √2]
    let u = d1 / d1_len;
    let length = d_max * d1_len; // may be ∞: then every hit is at fraction 0
    let (m, r) = (m / w, r / w);
    let cc = m.length_squared() - r * r;
    if cc <= 0.0 {
        return None; // origin inside (or on) the disc
    }
    let b = m.dot(u);
    if b >= 0.0 {
        return None; // moving away
    }
    let disc = b * b - cc;
    if disc < 0.0 {
        return None;
    }
    let t = cc / (-b + disc.sqrt());
    let s = t * (w / length);
    if !(s >= 0.0 && s <= ray.max_fraction) {
        return None; // beyond the ray (or ∞)
    }
    let normal = (m + t * u).try_normalize().unwrap_or(-u);
    Some(CastHit {
        point: ray.origin + s * d,
        normal,
        fraction: s,
    })
}

/// Ray against the segment `p1`–`p2` seen from its front side only
/// (`front` normal `right_perp(p2 - p1)`) when `one_sided`, from either side
/// otherwise. The normal faces the ray.
pub fn ray_segment(ray: &RayInput, p1: Vec2, p2: Vec2, one_sided: bool) -> Option<CastHit> {
    if !usable(ray) {
        return None;
    }
    let e = p2 - p1;
    let len = e.length();
    if len <= EPSILON {
        return None;
    }
    let n = right_perp(e / len);
    let d = ray.translation;
    let denom = n.dot(d);
    let dist0 = n.dot(ray.origin - p1);
    if denom == 0.0 {
        return None; // parallel
    }
    if one_sided && (dist0 <= 0.0 || denom >= 0.0) {
        return None;
    }
    let s = -dist0 / denom;
    if s < 0.0 || s > ray.max_fraction {
        return None;
    }
    let point = ray.origin + s * d;
    let along = (point - p1).dot(e) / (len * len);
    if !(0.0..=1.0).contains(&along) {
        return None;
    }
    let normal = if dist0 > 0.0 || (dist0 == 0.0 && denom < 0.0) {
        n
    } else {
        -n
    };
    Some(CastHit {
        point,
        normal,
        fraction: s,
    })
}

/// Ray against a one-sided chain segment (front side only).
pub fn ray_chain_segment(ray: &RayInput, c: &ChainSegment) -> Option<CastHit> {
    ray_segment(ray, c.segment.point1, c.segment.point2, true)
}

/// Ray against the capsule of core `p1`–`p2` and radius `r` (`r > 0`).
pub fn ray_rounded_segment(ray: &RayInput, p1: Vec2, p2: Vec2, r: Real) -> Option<CastHit> {
    if !usable(ray) || point_segment_distance_sq(ray.origin, p1, p2) <= r * r {
        return None;
    }
    let mut best: Option<CastHit> = None;
    let e = p2 - p1;
    let len = e.length();
    if len > EPSILON {
        let n = right_perp(e / len);
        for side in [n, -n] {
            let off = r * side;
            // One-sided towards `side`: the offset side of the capsule.
            let (a, b) = if side == n {
                (p1 + off, p2 + off)
            } else {
                (p2 + off, p1 + off)
            };
            keep_closest(&mut best, ray_segment(ray, a, b, true));
        }
    }
    keep_closest(&mut best, ray_disc(ray, p1, r));
    keep_closest(&mut best, ray_disc(ray, p2, r));
    best
}

/// Ray against a polygon (sharp, rounded, or a 2-vertex capsule core).
pub fn ray_polygon(ray: &RayInput, p: &Polygon) -> Option<CastHit> {
    if !usable(ray) || p.count == 0 || p.count > MAX_POLYGON_VERTICES {
        return None;
    }
    if p.count == 2 {
        return if p.radius > 0.0 {
            ray_rounded_segment(ray, p.vertices[0], p.vertices[1], p.radius)
        } else {
            ray_segment(ray, p.vertices[0], p.vertices[1], false)
        };
    }
    if p.radius > 0.0 {
        return ray_rounded_polygon(ray, p);
    }
    // Slab clipping: the ray segment against each edge half-plane.
    let d = ray.translation;
    let (mut lower, mut upper) = (0.0, ray.max_fraction);
    let mut index = None;
    for i in 0..p.count {
        let n = p.normals[i];
        let numerator = n.dot(p.vertices[i] - ray.origin);
        let denominator = n.dot(d);
        if denominator == 0.0 {
            if numerator < 0.0 {
                return None;
            }
        } else if denominator < 0.0 && numerator < lower * denominator {
            // Entering this half-plane later than any other so far.
            lower = numerator / denominator;
            index = Some(i);
        } else if denominator > 0.0 && numerator < upper * denominator {
            upper = numerator / denominator;
        }
        if upper < lower {
            return None;
        }
    }
    let i = index?; // None: the origin is inside
    Some(CastHit {
        point: ray.origin + lower * d,
        normal: p.normals[i],
        fraction: lower,
    })
}

/// A rounded polygon: the offset edges and the vertex discs.
fn ray_rounded_polygon(ray: &RayInput, p: &Polygon) -> Option<CastHit> {
    let n = p.count;
    if point_in_polygon_core(ray.origin, p)
        || (0..n).any(|i| {
            point_segment_distance_sq(ray.origin, p.vertices[i], p.vertices[(i + 1) % n])
                <= p.radius * p.radius
        })
    {
        return None;
    }
    let mut best = None;
    for i in 0..n {
        let off = p.radius * p.normals[i];
        let a = p.vertices[i] + off;
        let b = p.vertices[(i + 1) % n] + off;
        keep_closest(&mut best, ray_segment(ray, a, b, true));
        keep_closest(&mut best, ray_disc(ray, p.vertices[i], p.radius));
    }
    best
}

fn keep_closest(best: &mut Option<CastHit>, hit: Option<CastHit>) {
    if let Some(h) = hit
        && best.is_none_or(|b| h.fraction < b.fraction)
    {
        *best = Some(h);
    }
}

/// Squared distance from `x` to the segment `a`–`b`.
pub(crate) fn point_segment_distance_sq(x: Vec2, a: Vec2, b: Vec2) -> Real {
    let e = b - a;
    let ee = e.length_squared();
    let t = if ee > 0.0 {
        ((x - a).dot(e) / ee).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + t * e).distance_squared(x)
}

/// True when `x` is inside the core polygon (or on its boundary).
pub(crate) fn point_in_polygon_core(x: Vec2, p: &Polygon) -> bool {
    p.count >= 3 && (0..p.count).all(|i| p.normals[i].dot(x - p.vertices[i]) <= 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Capsule, Circle, Segment, make_chain};
    use crate::math::Rot;

    fn v(x: Real, y: Real) -> Vec2 {
        Vec2::new(x, y)
    }

    fn close(a: Vec2, b: Vec2) -> bool {
        (a - b).length() < 1e-5
    }

    #[test]
    fn ray_circle_matches_the_analytic_entry_point() {
        // Ray along y = 0.6 towards a unit circle at (2, 0): enters at x = 2 − 0.8.
        let s = Shape::Circle(Circle::new(v(2.0, 0.0), 1.0).unwrap());
        let ray = RayInput::new(v(0.0, 0.6), v(4.0, 0.0));
        let h = s.ray_cast(&Transform::IDENTITY, &ray).unwrap();
        assert!((h.fraction - 1.2 / 4.0).abs() < 1e-6, "{h:?}");
        assert!(close(h.point, v(1.2, 0.6)));
        assert!(close(h.normal, v(-0.8, 0.6)));
        // Too short, from inside, and pointing away: no hit.
        let short = RayInput {
            max_fraction: 0.29,
            ..ray
        };
        assert!(s.ray_cast(&Transform::IDENTITY, &short).is_none());
        let inside = RayInput::new(v(2.0, 0.0), v(4.0, 0.0));
        assert!(s.ray_cast(&Transform::IDENTITY, &inside).is_none());
        let away = RayInput::new(v(0.0, 0.0), v(-4.0, 0.0));
        assert!(s.ray_cast(&Transform::IDENTITY, &away).is_none());
    }

    #[test]
    fn ray_capsule_hits_side_and_cap() {
        let s = Shape::Capsule(Capsule::new(v(-1.0, 0.0), v(1.0, 0.0), 0.5).unwrap());
        let xf = Transform::IDENTITY;
        // Down onto the flat side.
        let h = s
            .ray_cast(&xf, &RayInput::new(v(0.3, 2.0), v(0.0, -4.0)))
            .unwrap();
        assert!((h.fraction - 1.5 / 4.0).abs() < 1e-6);
        assert!(close(h.normal, v(0.0, 1.0)));
        // Along the axis onto the cap: enters at x = −1.5.
        let h = s
            .ray_cast(&xf, &RayInput::new(v(-3.0, 0.0), v(3.0, 0.0)))
            .unwrap();
        assert!((h.fraction - 0.5).abs() < 1e-6);
        assert!(close(h.normal, v(-1.0, 0.0)));
        // Near the cap off axis: y = 0.3 meets the cap at x = −1 − 0.4.
        let h = s
            .ray_cast(&xf, &RayInput::new(v(-3.0, 0.3), v(3.0, 0.0)))
            .unwrap();
        assert!(close(h.point, v(-1.4, 0.3)));
        assert!(close(h.normal, v(-0.8, 0.6)));
        // Rotated and moved: the capsule stands vertically at (5, 0).
        let xf = Transform {
            p: v(5.0, 0.0),
            q: Rot::from_angle(crate::math::PI / 2.0),
        };
        let h = s
            .ray_cast(&xf, &RayInput::new(v(0.0, 0.0), v(10.0, 0.0)))
            .unwrap();
        assert!((h.fraction - 0.45).abs() < 1e-5);
        assert!(close(h.normal, v(-1.0, 0.0)));
    }

    #[test]
    fn ray_box_and_rounded_box() {
        let b = Shape::Polygon(Polygon::make_box(1.0, 0.5));
        let xf = Transform::new(v(3.0, 0.0), 0.0);
        let h = b
            .ray_cast(&xf, &RayInput::new(v(0.0, 0.2), v(4.0, 0.0)))
            .unwrap();
        assert!((h.fraction - 0.5).abs() < 1e-6);
        assert!(close(h.point, v(2.0, 0.2)));
        assert!(close(h.normal, v(-1.0, 0.0)));
        // Misses above the box, and from inside no hit.
        assert!(
            b.ray_cast(&xf, &RayInput::new(v(0.0, 0.6), v(4.0, 0.0)))
                .is_none()
        );
        assert!(
            b.ray_cast(&xf, &RayInput::new(v(3.0, 0.0), v(4.0, 0.0)))
                .is_none()
        );
        // Rounded box: half-widths 1 + 0.25; the corner disc at (1, 0.5).
        let r = Shape::Polygon(Polygon::make_rounded_box(1.0, 0.5, 0.25));
        let h = r
            .ray_cast(
                &Transform::IDENTITY,
                &RayInput::new(v(-5.0, 0.0), v(10.0, 0.0)),
            )
            .unwrap();
        assert!(close(h.point, v(-1.25, 0.0)));
        assert!(close(h.normal, v(-1.0, 0.0)));
        // Diagonal onto the corner disc centred at (1, 0.5).
        let dir = v(-1.0, -1.0).normalize();
        let origin = v(1.0, 0.5) - 3.0 * dir;
        let h = r
            .ray_cast(&Transform::IDENTITY, &RayInput::new(origin, 3.0 * dir))
            .unwrap();
        assert!((h.fraction - (3.0 - 0.25) / 3.0).abs() < 1e-5, "{h:?}");
        assert!(close(h.normal, -dir));
    }

    #[test]
    fn ray_segment_is_two_sided_and_chain_one_sided() {
        let s = Shape::Segment(Segment::new(v(0.0, -1.0), v(0.0, 1.0)).unwrap());
        let xf = Transform::IDENTITY;
        let from_left = s
            .ray_cast(&xf, &RayInput::new(v(-2.0, 0.5), v(4.0, 0.0)))
            .unwrap();
        assert!((from_left.fraction - 0.5).abs() < 1e-6);
        assert!(close(from_left.normal, v(-1.0, 0.0)));
        let from_right = s
            .ray_cast(&xf, &RayInput::new(v(2.0, 0.5), v(-4.0, 0.0)))
            .unwrap();
        assert!(close(from_right.normal, v(1.0, 0.0)));
        // Past the end: no hit.
        assert!(
            s.ray_cast(&xf, &RayInput::new(v(-2.0, 1.5), v(4.0, 0.0)))
                .is_none()
        );
        // Chain segment going +x: front is −y.
        let chain = make_chain(&[v(-1.0, 0.0), v(1.0, 0.0)], false).unwrap();
        let c = Shape::ChainSegment(chain[0]);
        let h = c
            .ray_cast(&xf, &RayInput::new(v(0.0, -2.0), v(0.0, 4.0)))
            .unwrap();
        assert!((h.fraction - 0.5).abs() < 1e-6);
        assert!(close(h.normal, v(0.0, -1.0)));
        assert!(
            c.ray_cast(&xf, &RayInput::new(v(0.0, 2.0), v(0.0, -4.0)))
                .is_none()
        );
    }

    #[test]
    fn zero_translation_hits_nothing() {
        let s = Shape::Circle(Circle::new(v(0.0, 0.0), 1.0).unwrap());
        assert!(
            s.ray_cast(
                &Transform::IDENTITY,
                &RayInput::new(v(-3.0, 0.0), Vec2::ZERO)
            )
            .is_none()
        );
    }
}
