//! Time of impact: the first moment two moving, turning convex shapes come
//! within a target distance of each other during a step.
//!
//! Each shape moves along a [`Sweep`]: its centre of mass goes linearly from
//! `c1` to `c2` and its angle from `a1` to `a2` as the fraction `t` goes from
//! 0 to 1. [`time_of_impact`] finds the first `t ≤ t_max` where the distance
//! between the cores reaches the target
//! `max(LINEAR_SLOP, r_a + r_b − LINEAR_SLOP)` (the surfaces then touch
//! within a linear slop, as Box2D's `b2TimeOfImpact`), by conservative
//! advancement on the GJK distance:
//!
//! ```text
//! t ← 0
//! loop: d = core distance at t (GJK), n = unit normal A → B
//!       d < target + tol            → Hit at t
//!       rate = −Δc·n + |Δa_a| R_a + |Δa_b| R_b    (bound on how fast d shrinks)
//!       rate ≤ 0                    → Separated
//!       t += (d − target) / rate;  t > t_max → Separated
//! ```
//!
//! `Δc` is the relative motion of the centres over the step and `R` the
//! largest distance of a core point from its centre of mass: without
//! rotation the distance is a convex function of `t`, so the step never
//! passes the first contact; with rotation the `|Δa| R` terms keep it short.
//! Should a step still overshoot (the distance falls below the target), the
//! root is found by bisection between the last safe fraction and the
//! overshoot. Shapes that already touch or overlap at `t = 0` are
//! [`ToiState::Overlapped`] with fraction 0 (the caller decides what to do).
//!
//! ```
//! use janus2d_core::geometry::{Circle, Polygon, Shape, ShapeProxy, Sweep, ToiState, time_of_impact};
//! use janus2d_core::math::{Transform, Vec2};
//! // A 0.5 m ball travels 10 m along +x at a wall whose face is at x = 5.
//! let ball = ShapeProxy::from_shape(&Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap()));
//! let wall = ShapeProxy::from_shape(&Shape::Polygon(Polygon::make_box(1.0, 1.0)));
//! let wall_sweep = Sweep::stationary(&Transform::new(Vec2::new(6.0, 0.0), 0.0));
//! let ball_sweep = Sweep::linear(Vec2::ZERO, Vec2::new(10.0, 0.0), 0.0);
//! let out = time_of_impact(&wall, &wall_sweep, &ball, &ball_sweep, 1.0);
//! assert_eq!(out.state, ToiState::Hit);
//! assert!((out.fraction - 0.45).abs() < 1e-3); // gap 4.5 m of 10 m travel
//! ```

use super::distance::{ShapeProxy, core_distance};
use super::shapes::{LINEAR_SLOP, Shape};
use crate::math::{EPSILON, Real, Rot, Transform, Vec2, vec_is_finite};

/// Iteration cap of the time-of-impact advancement (a count; usual 50).
pub const TOI_MAX_ITERATIONS: usize = 50;

/// Bisection steps after an overshoot (a count).
const TOI_ROOT_ITERATIONS: usize = 40;

/// The motion of a body over a step: centre of mass and angle, linear in
/// the fraction `t ∈ [0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sweep {
    /// Centre of mass in the body frame, m.
    pub local_center: Vec2,
    /// World centre of mass at `t = 0`, m.
    pub c1: Vec2,
    /// World centre of mass at `t = 1`, m.
    pub c2: Vec2,
    /// Angle at `t = 0`, rad.
    pub a1: Real,
    /// Angle at `t = 1`, rad (may differ from `a1` by more than π).
    pub a2: Real,
}

impl Sweep {
    /// A body that stays at `xf` (centre of mass at the origin).
    #[must_use]
    pub fn stationary(xf: &Transform) -> Sweep {
        let a = xf.q.angle();
        Sweep {
            local_center: Vec2::ZERO,
            c1: xf.p,
            c2: xf.p,
            a1: a,
            a2: a,
        }
    }

    /// A body with its centre of mass at its origin, moving from `p1` to
    /// `p2` at a fixed angle.
    #[must_use]
    pub fn linear(p1: Vec2, p2: Vec2, angle: Real) -> Sweep {
        Sweep {
            local_center: Vec2::ZERO,
            c1: p1,
            c2: p2,
            a1: angle,
            a2: angle,
        }
    }

    /// The sweep of a body from its pose at the start of a step (centre
    /// `center0`, rotation `rotation0`) to its pose now (centre `center`,
    /// rotation `rotation`), turning the shorter way.
    #[must_use]
    pub fn between(
        local_center: Vec2,
        center0: Vec2,
        rotation0: Rot,
        center: Vec2,
        rotation: Rot,
    ) -> Sweep {
        let a1 = rotation0.angle();
        Sweep {
            local_center,
            c1: center0,
            c2: center,
            a1,
            a2: a1 + rotation0.relative_angle(rotation),
        }
    }

    /// The centre of mass at fraction `t`.
    #[inline]
    #[must_use]
    pub fn center_at(&self, t: Real) -> Vec2 {
        self.c1 + t * (self.c2 - self.c1)
    }

    /// The body transform (origin and rotation) at fraction `t`.
    #[must_use]
    pub fn transform_at(&self, t: Real) -> Transform {
        let q = Rot::from_angle(self.a1 + t * (self.a2 - self.a1));
        let c = self.center_at(t);
        Transform {
            p: c - q.rotate(self.local_center),
            q,
        }
    }

    fn is_finite(&self) -> bool {
        vec_is_finite(self.local_center)
            && vec_is_finite(self.c1)
            && vec_is_finite(self.c2)
            && self.a1.is_finite()
            && self.a2.is_finite()
    }
}

/// How a time-of-impact search ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToiState {
    /// The shapes come within the target distance at `fraction`.
    Hit,
    /// The shapes stay apart up to `t_max` (`fraction = t_max`).
    Separated,
    /// The shapes touch or overlap at the start (`fraction = 0`).
    Overlapped,
    /// No answer within the iteration caps, or non-finite input; `fraction`
    /// is the last fraction known to be clear (0 for bad input).
    Failed,
}

/// The answer of [`time_of_impact`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToiOutput {
    /// How the search ended.
    pub state: ToiState,
    /// Fraction of the step, in `[0, t_max]`.
    pub fraction: Real,
}

/// Largest distance of a proxy's core points from `center` (body frame).
fn reach(proxy: &ShapeProxy, center: Vec2) -> Real {
    proxy.points[..proxy.count.clamp(1, proxy.points.len())]
        .iter()
        .map(|p| (*p - center).length())
        .fold(0.0, Real::max)
}

/// The first fraction `t ∈ [0, t_max]` at which B (moving along `sweep_b`)
/// comes within the target distance of A (moving along `sweep_a`); see the
/// module docs. `t_max` is clamped to `[0, 1]`.
#[must_use]
pub fn time_of_impact(
    proxy_a: &ShapeProxy,
    sweep_a: &Sweep,
    proxy_b: &ShapeProxy,
    sweep_b: &Sweep,
    t_max: Real,
) -> ToiOutput {
    if !(sweep_a.is_finite() && sweep_b.is_finite() && t_max.is_finite()) {
        return ToiOutput {
            state: ToiState::Failed,
            fraction: 0.0,
        };
    }
    let t_max = t_max.clamp(0.0, 1.0);
    let total_radius = proxy_a.radius + proxy_b.radius;
    let target = LINEAR_SLOP.max(total_radius - LINEAR_SLOP);
    let tolerance = 0.25 * LINEAR_SLOP;
    let rotation_bound = (sweep_a.a2 - sweep_a.a1).abs() * reach(proxy_a, sweep_a.local_center)
        + (sweep_b.a2 - sweep_b.a1).abs() * reach(proxy_b, sweep_b.local_center);
    let dc = (sweep_b.c2 - sweep_b.c1) - (sweep_a.c2 - sweep_a.c1);
    let distance_at = |t: Real| {
        let out = core_distance(
            proxy_a,
            &sweep_a.transform_at(t),
            proxy_b,
            &sweep_b.transform_at(t),
        );
        (out.distance, out.normal)
    };
    let mut t: Real = 0.0;
    let mut t_safe: Real = 0.0;
    for iteration in 0..TOI_MAX_ITERATIONS {
        let (d, normal) = distance_at(t);
        if d < target - tolerance {
            if iteration == 0 {
                return ToiOutput {
                    state: ToiState::Overlapped,
                    fraction: 0.0,
                };
            }
            // Overshot (rotation): bisect between the last clear fraction and here.
            return bisect(&distance_at, t_safe, t, target, tolerance);
        }
        if d < target + tolerance {
            return ToiOutput {
                state: if iteration == 0 {
                    ToiState::Overlapped
                } else {
                    ToiState::Hit
                },
                fraction: t,
            };
        }
        t_safe = t;
        let rate = -dc.dot(normal) + rotation_bound;
        if rate <= EPSILON * (1.0 + dc.length()) {
            break;
        }
        t += (d - target) / rate;
        if t > t_max {
            // The end of the range may still be an overshoot (rotation).
            let (d_end, _) = distance_at(t_max);
            if d_end < target - tolerance {
                return bisect(&distance_at, t_safe, t_max, target, tolerance);
            }
            if d_end < target + tolerance {
                return ToiOutput {
                    state: ToiState::Hit,
                    fraction: t_max,
                };
            }
            break;
        }
        if iteration + 1 == TOI_MAX_ITERATIONS {
            return ToiOutput {
                state: ToiState::Failed,
                fraction: t_safe,
            };
        }
    }
    ToiOutput {
        state: ToiState::Separated,
        fraction: t_max,
    }
}

/// Bisection on `distance(t) − target` between a clear `lo` and an
/// overshot `hi`; answers the first fraction within the tolerance, or the
/// clear end when the iterations run out.
fn bisect(
    distance_at: &impl Fn(Real) -> (Real, Vec2),
    mut lo: Real,
    mut hi: Real,
    target: Real,
    tolerance: Real,
) -> ToiOutput {
    for _ in 0..TOI_ROOT_ITERATIONS {
        let mid = 0.5 * (lo + hi);
        let (d, _) = distance_at(mid);
        if (d - target).abs() < tolerance {
            return ToiOutput {
                state: ToiState::Hit,
                fraction: mid,
            };
        }
        if d > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    ToiOutput {
        state: ToiState::Failed,
        fraction: lo,
    }
}

/// How far a shape reaches: the size tests of continuous collision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeExtent {
    /// Smallest distance from the shape's centroid to its surface, m (the
    /// radius of a circle or capsule, the nearest face of a polygon plus its
    /// rounding; 0 for a segment).
    pub min_extent: Real,
    /// Largest distance from the given point to the shape's surface, m.
    pub max_extent: Real,
    /// Largest distance from the given point to the shape's core (a
    /// circle's centre, a capsule's or segment's end points, a polygon's
    /// vertices: the shape without its rounding), m. A turn by `Δθ` about
    /// the point moves the region the shape covers by at most
    /// `|Δθ| · core_reach` (the rounding disc is unchanged by a turn), so
    /// a circle turning about its centre sweeps nothing new.
    pub core_reach: Real,
}

/// The extents of `shape` (body frame); `max_extent` is measured from
/// `origin` (the body's centre of mass or origin). As Box2D's
/// `b2ComputeShapeExtent`.
///
/// ```
/// use janus2d_core::geometry::{Polygon, Shape, shape_extent};
/// use janus2d_core::math::{Real, Vec2};
/// let e = shape_extent(&Shape::Polygon(Polygon::make_box(0.5, 2.0)), Vec2::ZERO);
/// assert!((e.min_extent - 0.5).abs() < 1e-6);
/// let corner: Real = (0.25 + 4.0 as Real).sqrt();
/// assert!((e.max_extent - corner).abs() < 1e-5);
/// ```
#[must_use]
pub fn shape_extent(shape: &Shape, origin: Vec2) -> ShapeExtent {
    let proxy = ShapeProxy::from_shape(shape);
    let core_reach = reach(&proxy, origin);
    let max_extent = core_reach + proxy.radius;
    let min_extent = match shape {
        Shape::Circle(c) => c.radius,
        Shape::Capsule(c) => c.radius,
        Shape::Polygon(p) => {
            let n = p.count.clamp(1, p.vertices.len());
            let c = p.centroid;
            let faces = if n >= 3 {
                (0..n)
                    .map(|i| p.normals[i].dot(p.vertices[i] - c))
                    .fold(Real::MAX, Real::min)
            } else {
                0.0
            };
            faces + p.radius
        }
        Shape::Segment(_) | Shape::ChainSegment(_) => 0.0,
    };
    ShapeExtent {
        core_reach,
        min_extent,
        max_extent,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Circle, Polygon, Segment};
    use crate::math::PI;

    fn v(x: Real, y: Real) -> Vec2 {
        Vec2::new(x, y)
    }

    fn proxy(s: Shape) -> ShapeProxy {
        ShapeProxy::from_shape(&s)
    }

    fn ball(r: Real) -> ShapeProxy {
        proxy(Shape::Circle(Circle::new(Vec2::ZERO, r).unwrap()))
    }

    #[test]
    fn ball_at_a_wall_hits_at_gap_over_travel() {
        let wall = proxy(Shape::Polygon(Polygon::make_box(1.0, 1.0)));
        let wall_sweep = Sweep::stationary(&Transform::new(v(6.0, 0.0), 0.0));
        for (r, travel) in [(0.5, 10.0), (0.025, 5.0), (0.1, 4.96)] {
            let s = Sweep::linear(v(0.0, 0.0), v(travel, 0.0), 0.0);
            let out = time_of_impact(&wall, &wall_sweep, &ball(r), &s, 1.0);
            assert_eq!(out.state, ToiState::Hit, "r {r}");
            // The core distance at the hit is max(slop, r − slop): the centre
            // stops at 5 − r + slop (or 5 − slop for a tiny ball).
            let stop = 5.0 - LINEAR_SLOP.max(r - LINEAR_SLOP);
            let expected = stop / travel;
            assert!(
                (out.fraction - expected).abs() * travel < 0.3 * LINEAR_SLOP,
                "r {r}: {} vs {expected}",
                out.fraction
            );
            // The surfaces overlap by at most the slop at the reported
            // fraction (by design exactly the slop for the larger balls, so
            // the bound carries a rounding margin of 1e-6 m).
            let xf = s.transform_at(out.fraction);
            assert!(
                xf.p.x + r <= 5.0 + LINEAR_SLOP + 1e-6,
                "r {r}: {}",
                xf.p.x + r
            );
        }
    }

    #[test]
    fn moving_wall_and_ball_meet_in_relative_motion() {
        // Both move: the wall comes left 2 m, the ball goes right 6 m.
        let wall = proxy(Shape::Polygon(Polygon::make_box(0.05, 1.0)));
        let wall_sweep = Sweep::linear(v(6.0, 0.0), v(4.0, 0.0), 0.0);
        let s = Sweep::linear(Vec2::ZERO, v(6.0, 0.0), 0.0);
        let out = time_of_impact(&wall, &wall_sweep, &ball(0.5), &s, 1.0);
        assert_eq!(out.state, ToiState::Hit);
        // Gap 6 − 0.05 − 0.5 = 5.45 closes at 8 per step (slop aside).
        let expected = (5.45 + LINEAR_SLOP) / 8.0;
        assert!((out.fraction - expected).abs() < 1e-3, "{out:?}");
    }

    #[test]
    fn rotating_bar_hits_the_ceiling_at_the_analytic_angle() {
        // A 2 m × 0.1 m bar turns a quarter turn about its centre under a
        // ceiling whose face is at y = 0.5. Its top reaches
        // y(θ) = sin θ + 0.05 cos θ; the hit is at y = 0.5 − slop.
        let bar = proxy(Shape::Polygon(Polygon::make_box(1.0, 0.05)));
        let ceiling = proxy(Shape::Polygon(Polygon::make_box(10.0, 5.0)));
        let ceiling_sweep = Sweep::stationary(&Transform::new(v(0.0, 5.5), 0.0));
        let s = Sweep {
            local_center: Vec2::ZERO,
            c1: Vec2::ZERO,
            c2: Vec2::ZERO,
            a1: 0.0,
            a2: 0.5 * PI,
        };
        let out = time_of_impact(&ceiling, &ceiling_sweep, &bar, &s, 1.0);
        assert_eq!(out.state, ToiState::Hit, "{out:?}");
        let top = |th: Real| th.sin() + 0.05 * th.cos();
        let (mut lo, mut hi): (Real, Real) = (0.0, 0.5 * PI);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if top(mid) < 0.5 - LINEAR_SLOP {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let expected = lo / (0.5 * PI);
        assert!(
            (out.fraction - expected).abs() < 2e-3,
            "{out:?} vs {expected}"
        );
    }

    #[test]
    fn parallel_receding_and_short_sweeps_are_separated() {
        let wall = proxy(Shape::Polygon(Polygon::make_box(1.0, 1.0)));
        let ws = Sweep::stationary(&Transform::new(v(6.0, 0.0), 0.0));
        let b = ball(0.5);
        for s in [
            Sweep::linear(v(0.0, 3.0), v(10.0, 3.0), 0.0), // passes above
            Sweep::linear(v(0.0, 0.0), v(-10.0, 0.0), 0.0), // moves away
            Sweep::linear(v(0.0, 0.0), v(4.0, 0.0), 0.0),  // stops short
        ] {
            let out = time_of_impact(&wall, &ws, &b, &s, 1.0);
            assert_eq!(out.state, ToiState::Separated, "{s:?}");
            assert_eq!(out.fraction, 1.0);
        }
        // Stopping short of the hit fraction by t_max.
        let s = Sweep::linear(Vec2::ZERO, v(10.0, 0.0), 0.0);
        let out = time_of_impact(&wall, &ws, &b, &s, 0.3);
        assert_eq!((out.state, out.fraction), (ToiState::Separated, 0.3));
    }

    #[test]
    fn overlap_at_start_and_bad_input() {
        let wall = proxy(Shape::Polygon(Polygon::make_box(1.0, 1.0)));
        let ws = Sweep::stationary(&Transform::IDENTITY);
        let s = Sweep::linear(v(0.5, 0.0), v(10.0, 0.0), 0.0);
        let out = time_of_impact(&wall, &ws, &ball(0.5), &s, 1.0);
        assert_eq!((out.state, out.fraction), (ToiState::Overlapped, 0.0));
        let bad = Sweep::linear(v(Real::NAN, 0.0), v(1.0, 0.0), 0.0);
        let out = time_of_impact(&wall, &ws, &ball(0.5), &bad, 1.0);
        assert_eq!((out.state, out.fraction), (ToiState::Failed, 0.0));
    }

    #[test]
    fn thin_segment_is_not_tunnelled_by_a_tiny_fast_ball() {
        // 5 cm ball, 5 m in one step, through a segment at x = 2.
        let seg = proxy(Shape::Segment(
            Segment::new(v(2.0, -1.0), v(2.0, 1.0)).unwrap(),
        ));
        let ss = Sweep::stationary(&Transform::IDENTITY);
        let s = Sweep::linear(Vec2::ZERO, v(5.0, 0.0), 0.0);
        let out = time_of_impact(&seg, &ss, &ball(0.025), &s, 1.0);
        assert_eq!(out.state, ToiState::Hit);
        let x = s.transform_at(out.fraction).p.x;
        assert!(x < 2.0 - 0.015 && x > 2.0 - 0.025, "{x}");
    }

    #[test]
    fn extents_of_each_shape() {
        let c = shape_extent(
            &Shape::Circle(Circle::new(v(1.0, 0.0), 0.5).unwrap()),
            Vec2::ZERO,
        );
        assert!((c.min_extent - 0.5).abs() < 1e-6 && (c.max_extent - 1.5).abs() < 1e-6);
        let s = shape_extent(
            &Shape::Segment(Segment::new(v(-1.0, 0.0), v(1.0, 0.0)).unwrap()),
            Vec2::ZERO,
        );
        assert_eq!(s.min_extent, 0.0);
        assert!((s.max_extent - 1.0).abs() < 1e-6);
        let r = shape_extent(
            &Shape::Polygon(Polygon::make_rounded_box(1.0, 0.5, 0.1)),
            Vec2::ZERO,
        );
        assert!((r.min_extent - 0.6).abs() < 1e-5, "{r:?}");
    }
}
