//! Shape queries: bounding boxes, projections, scaling and the area in front
//! of a line (the portal plane).

use super::aabb::Aabb;
use super::shapes::{Capsule, ChainSegment, Circle, Polygon, Segment, Shape};
use crate::math::{EPSILON, PI, Real, TAU, Transform, Vec2, cross};

impl Shape {
    /// World-space bounding box of the shape under `xf` (tight for every
    /// kind; a chain segment's ghosts are not included).
    pub fn compute_aabb(&self, xf: &Transform) -> Aabb {
        match self {
            Shape::Circle(c) => {
                let p = xf.apply(c.center);
                let r = Vec2::splat(c.radius);
                Aabb::new(p - r, p + r)
            }
            Shape::Capsule(c) => points_aabb(&[xf.apply(c.center1), xf.apply(c.center2)], c.radius),
            Shape::Polygon(p) => {
                let mut lower = xf.apply(p.vertices[0]);
                let mut upper = lower;
                for i in 1..p.count {
                    let v = xf.apply(p.vertices[i]);
                    lower = lower.min(v);
                    upper = upper.max(v);
                }
                let r = Vec2::splat(p.radius);
                Aabb::new(lower - r, upper + r)
            }
            Shape::Segment(s) => points_aabb(&[xf.apply(s.point1), xf.apply(s.point2)], 0.0),
            Shape::ChainSegment(c) => points_aabb(
                &[xf.apply(c.segment.point1), xf.apply(c.segment.point2)],
                0.0,
            ),
        }
    }

    /// The interval `(min, max)` of `dot(x, dir)` over all world points `x` of
    /// the shape under `xf`. `dir` should be a unit vector (then the interval
    /// is in metres). A shape is entirely behind a plane `(p, n)` when
    /// `support_extent(xf, n).1 <= dot(p, n)`.
    pub fn support_extent(&self, xf: &Transform, dir: Vec2) -> (Real, Real) {
        // Project in the local frame, then add the offset of the origin.
        let d = xf.q.inv_rotate(dir);
        let base = xf.p.dot(dir);
        let (lo, hi) = match self {
            Shape::Circle(c) => {
                let s = c.center.dot(d);
                let r = c.radius * d.length();
                (s - r, s + r)
            }
            Shape::Capsule(c) => {
                let (a, b) = (c.center1.dot(d), c.center2.dot(d));
                let r = c.radius * d.length();
                (a.min(b) - r, a.max(b) + r)
            }
            Shape::Polygon(p) => {
                let mut lo = p.vertices[0].dot(d);
                let mut hi = lo;
                for i in 1..p.count {
                    let s = p.vertices[i].dot(d);
                    lo = lo.min(s);
                    hi = hi.max(s);
                }
                let r = p.radius * d.length();
                (lo - r, hi + r)
            }
            Shape::Segment(s) => {
                let (a, b) = (s.point1.dot(d), s.point2.dot(d));
                (a.min(b), a.max(b))
            }
            Shape::ChainSegment(c) => {
                let (a, b) = (c.segment.point1.dot(d), c.segment.point2.dot(d));
                (a.min(b), a.max(b))
            }
        };
        (base + lo, base + hi)
    }

    /// The shape scaled by `factor` about the local point `about`: every point
    /// `x` maps to `about + factor (x - about)` and every length (radii
    /// included) is multiplied by `|factor|`, so areas scale by `factor²`.
    /// A negative factor is a scaling by `|factor|` combined with a half turn
    /// about `about` (normals are negated, vertex order stays
    /// counter-clockwise). `factor` should be finite and non-zero; zero gives
    /// a degenerate (zero-size) shape.
    pub fn scaled(&self, factor: Real, about: Vec2) -> Shape {
        let map = |x: Vec2| about + factor * (x - about);
        let k = factor.abs();
        match self {
            Shape::Circle(c) => Shape::Circle(Circle {
                center: map(c.center),
                radius: k * c.radius,
            }),
            Shape::Capsule(c) => Shape::Capsule(Capsule {
                center1: map(c.center1),
                center2: map(c.center2),
                radius: k * c.radius,
            }),
            Shape::Polygon(p) => {
                let mut q = *p;
                let sign = if factor < 0.0 { -1.0 } else { 1.0 };
                for i in 0..p.count {
                    q.vertices[i] = map(p.vertices[i]);
                    q.normals[i] = sign * p.normals[i];
                }
                q.radius = k * p.radius;
                q.centroid = map(p.centroid);
                Shape::Polygon(q)
            }
            Shape::Segment(s) => Shape::Segment(Segment {
                point1: map(s.point1),
                point2: map(s.point2),
            }),
            Shape::ChainSegment(c) => Shape::ChainSegment(ChainSegment {
                ghost1: map(c.ghost1),
                segment: Segment {
                    point1: map(c.segment.point1),
                    point2: map(c.segment.point2),
                },
                ghost2: map(c.ghost2),
            }),
        }
    }

    /// The shape moved by the rigid transform `xf` (every point `x` maps to
    /// `xf.apply(x)`, normals turn with `xf.q`): a shape placed at an
    /// offset and angle in its body's frame. Sizes and areas are kept.
    ///
    /// ```
    /// use janus2d_core::geometry::{Capsule, Shape};
    /// use janus2d_core::{Transform, Vec2};
    /// let c = Shape::Capsule(Capsule::new(Vec2::new(-1.0, 0.0), Vec2::new(1.0, 0.0), 0.2).unwrap());
    /// let moved = c.transformed(&Transform::new(Vec2::new(0.0, 3.0), std::f32::consts::FRAC_PI_2 as _));
    /// let Shape::Capsule(m) = moved else { unreachable!() };
    /// assert!((m.center1 - Vec2::new(0.0, 2.0)).length() < 1e-5);
    /// assert!((moved.area() - c.area()).abs() < 1e-5);
    /// ```
    #[must_use]
    pub fn transformed(&self, xf: &Transform) -> Shape {
        let map = |x: Vec2| xf.apply(x);
        match self {
            Shape::Circle(c) => Shape::Circle(Circle {
                center: map(c.center),
                radius: c.radius,
            }),
            Shape::Capsule(c) => Shape::Capsule(Capsule {
                center1: map(c.center1),
                center2: map(c.center2),
                radius: c.radius,
            }),
            Shape::Polygon(p) => {
                let mut q = *p;
                for i in 0..p.count {
                    q.vertices[i] = map(p.vertices[i]);
                    q.normals[i] = xf.q.rotate(p.normals[i]);
                }
                q.centroid = map(p.centroid);
                Shape::Polygon(q)
            }
            Shape::Segment(s) => Shape::Segment(Segment {
                point1: map(s.point1),
                point2: map(s.point2),
            }),
            Shape::ChainSegment(c) => Shape::ChainSegment(ChainSegment {
                ghost1: map(c.ghost1),
                segment: Segment {
                    point1: map(c.segment.point1),
                    point2: map(c.segment.point2),
                },
                ghost2: map(c.ghost2),
            }),
        }
    }

    /// Area (m²) of the part of the shape, placed in the world by `xf`, that
    /// lies on the side of the line through `plane_point` that `plane_normal`
    /// points to (`dot(x - plane_point, plane_normal) > 0`).
    ///
    /// Exact for every kind, rounded polygons and capsules included: the
    /// boundary of a rounded polygon is its offset edges and vertex arcs, and
    /// the clipped area is Green's theorem over the parts of that boundary in
    /// front of the line (with the origin on the line, the closing chord adds
    /// nothing). Circles use the circular-segment formula. Segments and chain
    /// segments have no area (0). `plane_normal` need not be unit; a zero
    /// normal gives 0.
    pub fn area_in_front(&self, xf: &Transform, plane_point: Vec2, plane_normal: Vec2) -> Real {
        let len = plane_normal.length();
        if len.is_nan() || len <= EPSILON {
            return 0.0;
        }
        // Plane in the shape's local frame.
        let n = xf.q.inv_rotate(plane_normal / len);
        let o = xf.apply_inv(plane_point);
        match self {
            Shape::Circle(c) => circle_area_in_front(n.dot(c.center - o), c.radius),
            Shape::Capsule(c) => {
                let p = Polygon::make_capsule(c.center1, c.center2, c.radius);
                rounded_polygon_area_in_front(&p, o, n)
            }
            Shape::Polygon(p) => rounded_polygon_area_in_front(p, o, n),
            Shape::Segment(_) | Shape::ChainSegment(_) => 0.0,
        }
    }
}

fn points_aabb(pts: &[Vec2; 2], r: Real) -> Aabb {
    let r = Vec2::splat(r);
    Aabb::new(pts[0].min(pts[1]) - r, pts[0].max(pts[1]) + r)
}

/// Area of a disc of radius `r` whose centre is at signed distance `h` in
/// front of a line, on the front side: `r² acos(-h/r) + h √(r² - h²)`.
fn circle_area_in_front(h: Real, r: Real) -> Real {
    if h >= r {
        return PI * r * r;
    }
    if h <= -r {
        return 0.0;
    }
    let x = (-h / r).clamp(-1.0, 1.0);
    r * r * x.acos() + h * (r * r - h * h).max(0.0).sqrt()
}

/// `∮ x dy - y dx` over the part of segment `a`→`b` in front of the line
/// through the origin with normal `n`.
#[inline]
fn clipped_segment_term(a: Vec2, b: Vec2, n: Vec2) -> Real {
    let da = n.dot(a);
    let db = n.dot(b);
    if da >= 0.0 && db >= 0.0 {
        cross(a, b)
    } else if da < 0.0 && db < 0.0 {
        0.0
    } else {
        let m = a + (da / (da - db)) * (b - a);
        if da >= 0.0 { cross(a, m) } else { cross(m, b) }
    }
}

/// `∮ x dy - y dx` over the arc of the circle (centre `c`, radius `r`) from
/// angle `a0` to `a1` (counter-clockwise).
#[inline]
fn arc_term(c: Vec2, r: Real, a0: Real, a1: Real) -> Real {
    let (s0, c0) = a0.sin_cos();
    let (s1, c1) = a1.sin_cos();
    r * cross(c, Vec2::new(c1 - c0, s1 - s0)) + r * r * (a1 - a0)
}

/// The Green's-theorem term of the part in front of the line (origin on the
/// line, unit normal `n`) of the arc centred at `c` that turns
/// counter-clockwise from direction `n_start` to `n_end` (at most a half turn).
fn clipped_arc_term(c: Vec2, r: Real, n_start: Vec2, n_end: Vec2, n: Vec2) -> Real {
    let sweep = cross(n_start, n_end).abs().atan2(n_start.dot(n_end));
    if sweep.is_nan() || sweep <= 0.0 {
        return 0.0;
    }
    let h = n.dot(c);
    if h <= -r {
        return 0.0;
    }
    // Circle points in front: angle within `half` of the normal's angle.
    let half = if h >= r {
        PI
    } else {
        (-h / r).clamp(-1.0, 1.0).acos()
    };
    let start = n_start.y.atan2(n_start.x);
    let delta = (n.y.atan2(n.x) - start).rem_euclid(TAU);
    let mut sum = 0.0;
    for k in [-1.0, 0.0, 1.0] {
        let lo = (delta - half + k * TAU).max(0.0);
        let hi = (delta + half + k * TAU).min(sweep);
        if hi > lo {
            sum += arc_term(c, r, start + lo, start + hi);
        }
    }
    sum
}

/// Exact clipped area of a (rounded) polygon, plane given by point `o` and
/// unit normal `n` in the polygon's frame.
fn rounded_polygon_area_in_front(p: &Polygon, o: Vec2, n: Vec2) -> Real {
    let count = p.count;
    let r = p.radius;
    let mut twice = 0.0;
    for i in 0..count {
        let j = if i + 1 < count { i + 1 } else { 0 };
        let vi = p.vertices[i] - o;
        let vj = p.vertices[j] - o;
        let ni = p.normals[i];
        twice += clipped_segment_term(vi + r * ni, vj + r * ni, n);
        if r > 0.0 {
            twice += clipped_arc_term(vj, r, ni, p.normals[j], n);
        }
    }
    (0.5 * twice).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::shapes::make_chain;

    /// Relative tolerance: 2e-5 holds in f32, 1e-10 in f64.
    #[cfg(not(feature = "f64"))]
    const REL: Real = 2e-5;
    #[cfg(feature = "f64")]
    const REL: Real = 1e-10;

    fn close(a: Real, b: Real) -> bool {
        (a - b).abs() <= REL * b.abs().max(1.0)
    }

    fn v(x: Real, y: Real) -> Vec2 {
        Vec2::new(x, y)
    }

    fn all_shapes() -> Vec<Shape> {
        vec![
            Shape::Circle(Circle::new(v(0.3, -0.2), 0.7).unwrap()),
            Shape::Capsule(Capsule::new(v(-0.5, 0.1), v(0.6, 0.4), 0.3).unwrap()),
            Shape::Polygon(Polygon::make_box(0.5, 0.5)),
            Shape::Polygon(Polygon::make_offset_box(0.8, 0.3, v(0.2, 0.1), 0.4)),
            Shape::Polygon(Polygon::make_rounded_box(0.6, 0.4, 0.15)),
            Shape::Polygon(
                Polygon::from_hull(&[v(0.0, 0.0), v(1.0, 0.2), v(0.7, 1.1), v(-0.3, 0.8)], 0.1)
                    .unwrap(),
            ),
        ]
    }

    #[test]
    fn aabb_of_rotated_box_and_capsule() {
        let b = Shape::Polygon(Polygon::make_box(1.0, 1.0));
        let xf = Transform::new(v(2.0, 3.0), PI / 4.0);
        let bb = b.compute_aabb(&xf);
        let s = (2.0 as Real).sqrt();
        assert!((bb.lower - v(2.0 - s, 3.0 - s)).length() < 1e-5);
        assert!((bb.upper - v(2.0 + s, 3.0 + s)).length() < 1e-5);
        let c = Shape::Capsule(Capsule::new(v(-1.0, 0.0), v(1.0, 0.0), 0.5).unwrap());
        let bb = c.compute_aabb(&Transform::new(v(0.0, 0.0), PI / 2.0));
        assert!((bb.lower - v(-0.5, -1.5)).length() < 1e-5);
        assert!((bb.upper - v(0.5, 1.5)).length() < 1e-5);
    }

    #[test]
    fn support_extent_matches_aabb_on_axes() {
        let xf = Transform::new(v(-1.0, 0.5), 0.8);
        for s in all_shapes() {
            let bb = s.compute_aabb(&xf);
            let (lo, hi) = s.support_extent(&xf, v(1.0, 0.0));
            assert!((lo - bb.lower.x).abs() < 1e-5 && (hi - bb.upper.x).abs() < 1e-5);
            let (lo, hi) = s.support_extent(&xf, v(0.0, 1.0));
            assert!((lo - bb.lower.y).abs() < 1e-5 && (hi - bb.upper.y).abs() < 1e-5);
            // A plane beyond the maximum sees nothing in front of it.
            let n = v(0.6, 0.8);
            let (_, hi) = s.support_extent(&xf, n);
            assert_eq!(s.area_in_front(&xf, n * (hi + 1e-3), n), 0.0);
        }
    }

    #[test]
    fn unit_box_cut_in_the_middle_is_half() {
        let b = Shape::Polygon(Polygon::make_box(0.5, 0.5));
        let xf = Transform::new(v(3.0, -1.0), 0.3);
        for angle in [0.0, 0.4, 1.3, 2.9, -2.0] {
            let n = v(Real::cos(angle), Real::sin(angle));
            let a = b.area_in_front(&xf, xf.p, n);
            assert!(close(a, 0.5), "angle {angle}: {a}");
        }
        // Cut at a quarter: x > 0.25 of [-0.5, 0.5]².
        let a = b.area_in_front(&Transform::IDENTITY, v(0.25, 0.0), v(1.0, 0.0));
        assert!(close(a, 0.25), "{a}");
    }

    #[test]
    fn circle_cut_matches_circular_segment() {
        let r = 0.7;
        let c = Shape::Circle(Circle::new(v(0.0, 0.0), r).unwrap());
        let xf = Transform::new(v(1.0, 2.0), 0.0);
        for h in [-0.9, -0.7, -0.3, 0.0, 0.2, 0.69, 1.0] {
            // Plane at distance h behind the centre: the centre is h in front.
            let a = c.area_in_front(&xf, v(1.0, 2.0 - h), v(0.0, 1.0));
            let d = -h;
            let expect = if d >= r {
                0.0
            } else if d <= -r {
                PI * r * r
            } else {
                // Segment beyond distance d: r² acos(d/r) - d √(r²-d²).
                r * r * (d / r).acos() - d * (r * r - d * d).sqrt()
            };
            assert!((a - expect).abs() < 1e-5, "h {h}: {a} vs {expect}");
        }
    }

    #[test]
    fn rounded_box_horizontal_cut_matches_hand_formula() {
        let (hx, hy, r) = (0.6, 0.4, 0.15);
        let s = Shape::Polygon(Polygon::make_rounded_box(hx, hy, r));
        for c in [-0.3, 0.0, 0.25] {
            let a = s.area_in_front(&Transform::IDENTITY, v(0.0, c), v(0.0, 1.0));
            let expect = (2.0 * hx + 2.0 * r) * (hy - c) + 2.0 * hx * r + 0.5 * PI * r * r;
            assert!(close(a, expect), "c {c}: {a} vs {expect}");
        }
        // Through a corner arc: y > hy + r/2 leaves a strip 2hx wide plus two
        // circular-segment pieces of the corner discs.
        let cut = hy + 0.5 * r;
        let a = s.area_in_front(&Transform::IDENTITY, v(0.0, cut), v(0.0, 1.0));
        let seg = 0.5 * (r * r * (0.5 as Real).acos() - 0.5 * r * (r * r - 0.25 * r * r).sqrt());
        let expect = 2.0 * hx * 0.5 * r + 2.0 * seg;
        assert!(close(a, expect), "{a} vs {expect}");
    }

    #[test]
    fn capsule_cut_in_the_middle_is_half_and_end_cut_is_a_segment() {
        let cap = Capsule::new(v(-1.0, 0.0), v(1.0, 0.0), 0.3).unwrap();
        let s = Shape::Capsule(cap);
        let xf = Transform::new(v(0.5, 0.5), 1.0);
        for angle in [0.0, 0.5, 1.5, 2.5] {
            let n = v(Real::cos(angle), Real::sin(angle));
            let a = s.area_in_front(&xf, xf.p, n);
            assert!(close(a, 0.5 * cap.area()), "angle {angle}: {a}");
        }
        // Cut across the end cap: x > 1.1 leaves a circular segment.
        let a = s.area_in_front(&Transform::IDENTITY, v(1.1, 0.0), v(1.0, 0.0));
        let (r, d): (Real, Real) = (0.3, 0.1);
        let expect = r * r * (d / r).acos() - d * (r * r - d * d).sqrt();
        assert!(close(a, expect), "{a} vs {expect}");
        // Cut along the axis through both caps.
        let a = s.area_in_front(&Transform::IDENTITY, v(0.0, 0.1), v(0.0, 1.0));
        let expect = 2.0 * 0.2 + 2.0 * 0.5 * (r * r * (d / r).acos() - d * (r * r - d * d).sqrt());
        assert!(close(a, expect), "{a} vs {expect}");
    }

    #[test]
    fn front_and_back_areas_sum_to_the_total() {
        let xf = Transform::new(v(0.2, -0.4), 2.2);
        for s in all_shapes() {
            let total = s.area();
            for (k, angle) in [0.1 as Real, 0.9, 2.0, 3.0, 4.4, 5.5]
                .into_iter()
                .enumerate()
            {
                let n = v(angle.cos(), angle.sin());
                let p = xf.p + (k as Real * 0.17 - 0.4) * v(1.0, 0.3);
                let f = s.area_in_front(&xf, p, n);
                let b = s.area_in_front(&xf, p, -n);
                assert!(f >= 0.0 && b >= 0.0);
                assert!(
                    close(f + b, total),
                    "{s:?} angle {angle}: {f} + {b} vs {total}"
                );
            }
            // Far planes.
            assert!(close(
                s.area_in_front(&xf, xf.p - v(10.0, 0.0), v(1.0, 0.0)),
                total
            ));
            assert_eq!(s.area_in_front(&xf, xf.p + v(10.0, 0.0), v(1.0, 0.0)), 0.0);
        }
    }

    #[test]
    fn scaled_shapes_scale_area_by_factor_squared() {
        let about = v(0.1, -0.3);
        for s in all_shapes() {
            for f in [2.0, 0.5, -1.5] {
                let t = s.scaled(f, about);
                assert!(close(t.area(), f * f * s.area()), "{s:?} × {f}");
                let m0 = s.compute_mass(1.0);
                let m1 = t.compute_mass(1.0);
                let c = about + f * (m0.center - about);
                assert!((m1.center - c).length() < 1e-4, "{s:?} × {f}");
                assert!(close(
                    m1.rotational_inertia,
                    f.powi(4) * m0.rotational_inertia
                ));
                // Same cut plane through the mapped centre halves consistently.
                let n = v(0.6, 0.8);
                let a0 = s.area_in_front(&Transform::IDENTITY, m0.center, n);
                let nn = if f < 0.0 { -n } else { n };
                let a1 = t.area_in_front(&Transform::IDENTITY, c, nn);
                assert!(close(a1, f * f * a0), "{s:?} × {f}: {a1} vs {}", f * f * a0);
            }
        }
        let chain = make_chain(&[v(0.0, 0.0), v(1.0, 0.0), v(2.0, 1.0)], false).unwrap();
        let s = Shape::ChainSegment(chain[0]).scaled(2.0, v(0.0, 0.0));
        match s {
            Shape::ChainSegment(c) => {
                assert_eq!(c.segment.point2, v(2.0, 0.0));
                assert_eq!(c.ghost2, v(4.0, 2.0));
            }
            _ => unreachable!(),
        }
    }
}
