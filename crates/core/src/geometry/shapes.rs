//! Shape types, their validating constructors, the convex hull and the chain
//! builder.
//!
//! All shapes are given in their body's local frame. Polygons are convex,
//! counter-clockwise, with at most [`MAX_POLYGON_VERTICES`] vertices and an
//! optional rounding radius (the shape is the core polygon grown by the
//! radius in every direction).

use std::fmt;

use crate::math::{EPSILON, Real, Rot, Vec2, cross, vec_is_finite};

/// Collision tolerance in metres (usual value 0.005 m = 5 mm).
///
/// Contacts are allowed to penetrate this much so that resting contacts stay
/// touching; the hull welds points closer than half of it.
pub const LINEAR_SLOP: Real = 0.005;

/// Speculative contact distance in metres (usual value 0.02 m = 4 ×
/// [`LINEAR_SLOP`]): [`collide`](super::collide) reports contact points whose
/// separation is below the distance it is given, and this is the shared
/// setting to give it.
pub const SPECULATIVE_DISTANCE: Real = 4.0 * LINEAR_SLOP;

/// Maximum number of polygon vertices (a count; usual value 8).
pub const MAX_POLYGON_VERTICES: usize = 8;

/// Weld distance of [`Polygon::from_hull`] and [`make_chain`] in metres
/// (usual value 0.0025 m = 0.5 × [`LINEAR_SLOP`]): points closer than this
/// are merged, and a hull vertex closer than this to the line through its
/// neighbours is dropped.
pub const WELD_DISTANCE: Real = 0.5 * LINEAR_SLOP;

/// Why a shape could not be built.
#[derive(Debug, Clone, PartialEq)]
pub enum GeometryError {
    /// A coordinate, radius or extent is NaN or infinite.
    NonFinite,
    /// A circle or capsule radius is zero or negative.
    NonPositiveRadius,
    /// A polygon rounding radius is negative.
    NegativeRadius,
    /// Fewer distinct points (after welding) than the shape needs.
    TooFewPoints {
        /// Distinct points found.
        found: usize,
        /// Points needed: 3 for a polygon or a closed chain, 2 for an open chain.
        needed: usize,
    },
    /// All points lie on one line (within [`WELD_DISTANCE`]).
    CollinearPoints,
    /// The polygon has no (numerical) area.
    DegeneratePolygon,
    /// The convex hull has more than [`MAX_POLYGON_VERTICES`] vertices.
    TooManyVertices {
        /// Number of hull vertices found.
        count: usize,
    },
    /// A segment, capsule core or chain link is shorter than [`WELD_DISTANCE`].
    DegenerateSegment,
    /// A coordinate or radius beyond `max` (the stated shape extent,
    /// [`MAX_EXTENT`](crate::limits::MAX_EXTENT)), m.
    ExtentTooLarge {
        /// The limit, m.
        max: Real,
    },
    /// A hand-built polygon whose normal of edge `edge` is not the unit
    /// outward normal of that edge (within 1e-3).
    BadNormal {
        /// The edge index.
        edge: usize,
    },
    /// A hand-built polygon whose `centroid` lies outside its core.
    CentroidOutside,
}

impl fmt::Display for GeometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GeometryError::NonFinite => write!(f, "non-finite coordinate or radius"),
            GeometryError::NonPositiveRadius => write!(f, "radius must be positive"),
            GeometryError::NegativeRadius => write!(f, "rounding radius must not be negative"),
            GeometryError::TooFewPoints { found, needed } => {
                write!(f, "{found} distinct points, at least {needed} needed")
            }
            GeometryError::CollinearPoints => write!(f, "points are collinear"),
            GeometryError::DegeneratePolygon => write!(f, "polygon has zero area"),
            GeometryError::TooManyVertices { count } => write!(
                f,
                "convex hull has {count} vertices, at most {MAX_POLYGON_VERTICES} allowed"
            ),
            GeometryError::DegenerateSegment => {
                write!(f, "segment is shorter than the weld distance")
            }
            GeometryError::ExtentTooLarge { max } => {
                write!(
                    f,
                    "a coordinate or radius exceeds the shape extent {max:e} m"
                )
            }
            GeometryError::BadNormal { edge } => {
                write!(
                    f,
                    "normal {edge} is not the unit outward normal of its edge"
                )
            }
            GeometryError::CentroidOutside => write!(f, "polygon centroid lies outside it"),
        }
    }
}

impl std::error::Error for GeometryError {}

/// The right-hand perpendicular `(v.y, -v.x)`: the outward normal direction of
/// an edge of a counter-clockwise polygon.
#[inline(always)]
pub(crate) fn right_perp(v: Vec2) -> Vec2 {
    Vec2::new(v.y, -v.x)
}

/// `v / |v|`, or `fallback` when `|v|` is not above machine epsilon.
#[inline(always)]
pub(crate) fn normalize_or(v: Vec2, fallback: Vec2) -> Vec2 {
    let len = v.length();
    if len > EPSILON { v / len } else { fallback }
}

/// A solid disc.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Circle {
    /// Centre in the body frame, metres.
    pub center: Vec2,
    /// Radius, metres (positive).
    pub radius: Real,
}

impl Circle {
    /// A circle; errors on a non-finite input or a radius that is not positive.
    pub fn new(center: Vec2, radius: Real) -> Result<Circle, GeometryError> {
        if !vec_is_finite(center) || !radius.is_finite() {
            return Err(GeometryError::NonFinite);
        }
        if radius <= 0.0 {
            return Err(GeometryError::NonPositiveRadius);
        }
        Ok(Circle { center, radius })
    }
}

/// A solid capsule: all points within `radius` of the core segment
/// `center1`–`center2`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Capsule {
    /// First end of the core segment (body frame), metres.
    pub center1: Vec2,
    /// Second end of the core segment (body frame), metres.
    pub center2: Vec2,
    /// Radius, metres (positive).
    pub radius: Real,
}

impl Capsule {
    /// A capsule; errors on a non-finite input, a radius that is not positive,
    /// or a core shorter than [`WELD_DISTANCE`]
    /// ([`GeometryError::DegenerateSegment`]: use a [`Circle`] instead).
    pub fn new(center1: Vec2, center2: Vec2, radius: Real) -> Result<Capsule, GeometryError> {
        if !vec_is_finite(center1) || !vec_is_finite(center2) || !radius.is_finite() {
            return Err(GeometryError::NonFinite);
        }
        if radius <= 0.0 {
            return Err(GeometryError::NonPositiveRadius);
        }
        if center1.distance_squared(center2) < WELD_DISTANCE * WELD_DISTANCE {
            return Err(GeometryError::DegenerateSegment);
        }
        Ok(Capsule {
            center1,
            center2,
            radius,
        })
    }

    /// Length of the core segment, metres.
    #[inline]
    pub fn length(&self) -> Real {
        self.center1.distance(self.center2)
    }
}

/// A two-sided line segment without area (usually on static bodies).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Segment {
    /// First end point (body frame), metres.
    pub point1: Vec2,
    /// Second end point (body frame), metres.
    pub point2: Vec2,
}

impl Segment {
    /// A segment; errors on a non-finite input or one shorter than
    /// [`WELD_DISTANCE`].
    pub fn new(point1: Vec2, point2: Vec2) -> Result<Segment, GeometryError> {
        if !vec_is_finite(point1) || !vec_is_finite(point2) {
            return Err(GeometryError::NonFinite);
        }
        if point1.distance_squared(point2) < WELD_DISTANCE * WELD_DISTANCE {
            return Err(GeometryError::DegenerateSegment);
        }
        Ok(Segment { point1, point2 })
    }
}

/// A one-sided segment of a chain, with the neighbouring chain points
/// ("ghost" vertices) used to collide smoothly across internal vertices.
///
/// **Side convention (Box2D's).** With `d = point2 - point1`, the front normal
/// is `(d.y, -d.x) / |d|`, the right-hand side of the direction of travel.
/// Other shapes collide only from the front: a closed loop given
/// counter-clockwise collides from the outside (like a polygon), terrain
/// meant to be walked on from above runs right to left. A shape whose centre
/// (centroid) is behind the segment gets no contact.
///
/// **Ghosts.** `ghost1` is the chain point before `point1`, `ghost2` the one
/// after `point2`. A ghost within [`WELD_DISTANCE`] of its end point means "no
/// neighbour": that end is an exposed, rounded corner. [`make_chain`] sets
/// ghosts this way at the two ends of an open chain.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ChainSegment {
    /// The chain point before `segment.point1` (or `point1` itself at an open end).
    pub ghost1: Vec2,
    /// The segment itself.
    pub segment: Segment,
    /// The chain point after `segment.point2` (or `point2` itself at an open end).
    pub ghost2: Vec2,
}

impl ChainSegment {
    /// The unit front normal `(d.y, -d.x) / |d|` (see the type docs), or `(0, 1)`
    /// for a degenerate segment.
    #[inline]
    pub fn normal(&self) -> Vec2 {
        right_perp(normalize_or(
            self.segment.point2 - self.segment.point1,
            Vec2::new(-1.0, 0.0),
        ))
    }
}

/// Builds the one-sided segments of a chain through `points`.
///
/// An open chain (`closed_loop == false`) has `points.len() - 1` segments and
/// needs at least 2 points; its two end vertices have no neighbour (ghost set
/// equal to the end point, so the ends are rounded). A closed loop has
/// `points.len()` segments (the last one joins the last point to the first)
/// and needs at least 3 points. Consecutive points closer than
/// [`WELD_DISTANCE`] are an error ([`GeometryError::DegenerateSegment`]).
/// See [`ChainSegment`] for the side convention.
pub fn make_chain(points: &[Vec2], closed_loop: bool) -> Result<Vec<ChainSegment>, GeometryError> {
    if points.iter().any(|p| !vec_is_finite(*p)) {
        return Err(GeometryError::NonFinite);
    }
    let n = points.len();
    let needed = if closed_loop { 3 } else { 2 };
    if n < needed {
        return Err(GeometryError::TooFewPoints { found: n, needed });
    }
    let links = if closed_loop { n } else { n - 1 };
    for i in 0..links {
        let j = (i + 1) % n;
        if points[i].distance_squared(points[j]) < WELD_DISTANCE * WELD_DISTANCE {
            return Err(GeometryError::DegenerateSegment);
        }
    }
    let mut out = Vec::with_capacity(links);
    for i in 0..links {
        let p1 = points[i];
        let p2 = points[(i + 1) % n];
        let (ghost1, ghost2) = if closed_loop {
            (points[(i + n - 1) % n], points[(i + 2) % n])
        } else {
            let g1 = if i > 0 { points[i - 1] } else { p1 };
            let g2 = if i + 2 < n { points[i + 2] } else { p2 };
            (g1, g2)
        };
        out.push(ChainSegment {
            ghost1,
            segment: Segment {
                point1: p1,
                point2: p2,
            },
            ghost2,
        });
    }
    Ok(out)
}

/// A convex polygon with up to [`MAX_POLYGON_VERTICES`] counter-clockwise
/// vertices, optionally rounded by `radius`.
///
/// `normals[i]` is the outward unit normal of the edge from `vertices[i]` to
/// `vertices[(i + 1) % count]`. Entries at `count..` are unused (zero). A
/// polygon with `count == 2` is a capsule core (see [`Polygon::make_capsule`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Polygon {
    /// Vertices (body frame, counter-clockwise), metres.
    pub vertices: [Vec2; MAX_POLYGON_VERTICES],
    /// Outward unit edge normals.
    pub normals: [Vec2; MAX_POLYGON_VERTICES],
    /// Number of vertices in use (2 to [`MAX_POLYGON_VERTICES`]).
    pub count: usize,
    /// Rounding radius, metres (0 for a sharp polygon).
    pub radius: Real,
    /// Area centroid of the core polygon (body frame), metres.
    pub centroid: Vec2,
}

impl Polygon {
    /// An axis-aligned box centred on the body origin with half-widths `hx`, `hy`.
    ///
    /// A convenience for sizes written in the code (a level's literals):
    /// the checked constructor is [`try_make_box`](Self::try_make_box),
    /// which returns a [`GeometryError`] instead of panicking; use it for
    /// sizes computed or read at run time.
    ///
    /// # Panics
    /// If `hx` or `hy` is not finite and positive.
    pub fn make_box(hx: Real, hy: Real) -> Polygon {
        Self::make_offset_rounded_box(hx, hy, Vec2::ZERO, Rot::IDENTITY, 0.0)
    }

    /// A box with half-widths `hx`, `hy`, centred on `center` and turned by
    /// `angle` radians (all in the body frame). A convenience for literals;
    /// [`try_make_offset_box`](Self::try_make_offset_box) is the checked
    /// constructor.
    ///
    /// # Panics
    /// If `hx` or `hy` is not finite and positive, or `center`/`angle` is not finite.
    pub fn make_offset_box(hx: Real, hy: Real, center: Vec2, angle: Real) -> Polygon {
        assert!(
            vec_is_finite(center) && angle.is_finite(),
            "make_offset_box: non-finite centre or angle"
        );
        Self::make_offset_rounded_box(hx, hy, center, Rot::from_angle(angle), 0.0)
    }

    /// A box with core half-widths `hx`, `hy` rounded by `radius` (the outer
    /// half-widths are `hx + radius`, `hy + radius`). A convenience for
    /// literals; [`try_make_rounded_box`](Self::try_make_rounded_box) is the
    /// checked constructor.
    ///
    /// # Panics
    /// If `hx` or `hy` is not finite and positive, or `radius` is negative or
    /// not finite.
    pub fn make_rounded_box(hx: Real, hy: Real, radius: Real) -> Polygon {
        Self::make_offset_rounded_box(hx, hy, Vec2::ZERO, Rot::IDENTITY, radius)
    }

    fn make_offset_rounded_box(hx: Real, hy: Real, center: Vec2, q: Rot, radius: Real) -> Polygon {
        assert!(
            hx.is_finite() && hy.is_finite() && hx > 0.0 && hy > 0.0,
            "box half-widths must be finite and positive (got {hx}, {hy})"
        );
        assert!(
            radius.is_finite() && radius >= 0.0,
            "box rounding radius must be finite and non-negative (got {radius})"
        );
        let local = [
            Vec2::new(-hx, -hy),
            Vec2::new(hx, -hy),
            Vec2::new(hx, hy),
            Vec2::new(-hx, hy),
        ];
        let local_n = [
            Vec2::new(0.0, -1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 1.0),
            Vec2::new(-1.0, 0.0),
        ];
        let mut p = Polygon {
            vertices: [Vec2::ZERO; MAX_POLYGON_VERTICES],
            normals: [Vec2::ZERO; MAX_POLYGON_VERTICES],
            count: 4,
            radius,
            centroid: center,
        };
        for i in 0..4 {
            p.vertices[i] = q.rotate(local[i]) + center;
            p.normals[i] = q.rotate(local_n[i]);
        }
        p
    }

    /// [`make_box`](Self::make_box) that returns an error instead of
    /// panicking: [`GeometryError::NonFinite`] for a NaN or infinite
    /// half-width, [`GeometryError::DegeneratePolygon`] for one ≤ 0.
    ///
    /// ```
    /// use janus2d_core::geometry::{GeometryError, Polygon};
    /// assert_eq!(Polygon::try_make_box(0.0, 1.0), Err(GeometryError::DegeneratePolygon));
    /// assert!(Polygon::try_make_box(0.5, 1.0).is_ok());
    /// ```
    pub fn try_make_box(hx: Real, hy: Real) -> Result<Polygon, GeometryError> {
        Self::try_make_offset_rounded_box(hx, hy, Vec2::ZERO, 0.0, 0.0)
    }

    /// [`make_offset_box`](Self::make_offset_box) that returns an error
    /// instead of panicking (non-finite input, a half-width ≤ 0).
    pub fn try_make_offset_box(
        hx: Real,
        hy: Real,
        center: Vec2,
        angle: Real,
    ) -> Result<Polygon, GeometryError> {
        Self::try_make_offset_rounded_box(hx, hy, center, angle, 0.0)
    }

    /// [`make_rounded_box`](Self::make_rounded_box) that returns an error
    /// instead of panicking (non-finite input, a half-width ≤ 0, a negative
    /// radius: [`GeometryError::NegativeRadius`]).
    pub fn try_make_rounded_box(
        hx: Real,
        hy: Real,
        radius: Real,
    ) -> Result<Polygon, GeometryError> {
        Self::try_make_offset_rounded_box(hx, hy, Vec2::ZERO, 0.0, radius)
    }

    /// A box with core half-widths `hx`, `hy`, centred on `center`, turned
    /// by `angle` radians (body frame) and rounded by `radius`: the general
    /// checked box constructor. Errors: non-finite input
    /// ([`GeometryError::NonFinite`]), a half-width ≤ 0
    /// ([`GeometryError::DegeneratePolygon`]), a negative radius
    /// ([`GeometryError::NegativeRadius`]).
    ///
    /// ```
    /// use janus2d_core::geometry::{GeometryError, Polygon};
    /// use janus2d_core::math::Vec2;
    /// let p = Polygon::try_make_offset_rounded_box(1.0, 0.5, Vec2::new(2.0, 0.0), 0.0, 0.1).unwrap();
    /// assert_eq!(p.centroid, Vec2::new(2.0, 0.0));
    /// assert_eq!(p.radius, 0.1);
    /// assert_eq!(
    ///     Polygon::try_make_offset_rounded_box(1.0, 0.5, Vec2::ZERO, 0.0, -0.1),
    ///     Err(GeometryError::NegativeRadius)
    /// );
    /// ```
    pub fn try_make_offset_rounded_box(
        hx: Real,
        hy: Real,
        center: Vec2,
        angle: Real,
        radius: Real,
    ) -> Result<Polygon, GeometryError> {
        let finite = hx.is_finite()
            && hy.is_finite()
            && radius.is_finite()
            && vec_is_finite(center)
            && angle.is_finite();
        if !finite {
            return Err(GeometryError::NonFinite);
        }
        if hx <= 0.0 || hy <= 0.0 {
            return Err(GeometryError::DegeneratePolygon);
        }
        if radius < 0.0 {
            return Err(GeometryError::NegativeRadius);
        }
        Ok(Self::make_offset_rounded_box(
            hx,
            hy,
            center,
            Rot::from_angle(angle),
            radius,
        ))
    }

    /// A validated capsule polygon ([`make_capsule`](Self::make_capsule)):
    /// errors for non-finite input, a radius ≤ 0
    /// ([`GeometryError::NonPositiveRadius`]) or a core shorter than
    /// [`WELD_DISTANCE`] ([`GeometryError::DegenerateSegment`]).
    pub fn try_make_capsule(p1: Vec2, p2: Vec2, radius: Real) -> Result<Polygon, GeometryError> {
        if !(vec_is_finite(p1) && vec_is_finite(p2) && radius.is_finite()) {
            return Err(GeometryError::NonFinite);
        }
        if radius <= 0.0 {
            return Err(GeometryError::NonPositiveRadius);
        }
        if (p2 - p1).length() <= WELD_DISTANCE {
            return Err(GeometryError::DegenerateSegment);
        }
        Ok(Self::make_capsule(p1, p2, radius))
    }

    /// A capsule as a 2-vertex rounded polygon (`count == 2`): the core
    /// segment `p1`–`p2` with `normals[0] = right_perp(p2 - p1)` normalised and
    /// `normals[1] = -normals[0]`. With `radius == 0` this is a segment.
    /// The collision code uses this form for capsules and segments against
    /// polygons. Inputs are not validated; a zero-length core gets the normal
    /// `(0, -1)`.
    pub fn make_capsule(p1: Vec2, p2: Vec2, radius: Real) -> Polygon {
        let n = right_perp(normalize_or(p2 - p1, Vec2::new(1.0, 0.0)));
        let mut p = Polygon {
            vertices: [Vec2::ZERO; MAX_POLYGON_VERTICES],
            normals: [Vec2::ZERO; MAX_POLYGON_VERTICES],
            count: 2,
            radius,
            centroid: 0.5 * (p1 + p2),
        };
        p.vertices[0] = p1;
        p.vertices[1] = p2;
        p.normals[0] = n;
        p.normals[1] = -n;
        p
    }

    /// The convex hull of `points`, rounded by `radius` (0 for sharp corners).
    ///
    /// Points closer than [`WELD_DISTANCE`] are welded (the first one is kept);
    /// hull vertices closer than [`WELD_DISTANCE`] to the line through their
    /// neighbours are dropped. Errors: non-finite input
    /// ([`GeometryError::NonFinite`]), negative radius, fewer than 3 distinct
    /// points, collinear points, zero area, more than
    /// [`MAX_POLYGON_VERTICES`] hull vertices. Any number of input points is
    /// accepted (interior points are discarded). Allocates; not for the hot
    /// path.
    pub fn from_hull(points: &[Vec2], radius: Real) -> Result<Polygon, GeometryError> {
        if !radius.is_finite() || points.iter().any(|p| !vec_is_finite(*p)) {
            return Err(GeometryError::NonFinite);
        }
        if radius < 0.0 {
            return Err(GeometryError::NegativeRadius);
        }
        let weld_sq = WELD_DISTANCE * WELD_DISTANCE;
        let mut pts: Vec<Vec2> = Vec::with_capacity(points.len());
        for &p in points {
            if pts.iter().all(|q| q.distance_squared(p) >= weld_sq) {
                pts.push(p);
            }
        }
        if pts.len() < 3 {
            return Err(GeometryError::TooFewPoints {
                found: pts.len(),
                needed: 3,
            });
        }
        let mut hull = monotone_chain(&mut pts);
        remove_collinear(&mut hull);
        if hull.len() < 3 {
            return Err(GeometryError::CollinearPoints);
        }
        if hull.len() > MAX_POLYGON_VERTICES {
            return Err(GeometryError::TooManyVertices { count: hull.len() });
        }
        let n = hull.len();
        let mut poly = Polygon {
            vertices: [Vec2::ZERO; MAX_POLYGON_VERTICES],
            normals: [Vec2::ZERO; MAX_POLYGON_VERTICES],
            count: n,
            radius,
            centroid: Vec2::ZERO,
        };
        for i in 0..n {
            poly.vertices[i] = hull[i];
            let edge = hull[(i + 1) % n] - hull[i];
            poly.normals[i] = right_perp(normalize_or(edge, Vec2::new(1.0, 0.0)));
        }
        let (area, centroid) = core_area_centroid(&poly.vertices[..n]);
        if !area.is_finite() || area <= 0.0 {
            return Err(GeometryError::DegeneratePolygon);
        }
        poly.centroid = centroid;
        Ok(poly)
    }

    /// Area of the core polygon (without the rounding), square metres.
    #[inline]
    pub fn core_area(&self) -> Real {
        core_area_centroid(&self.vertices[..self.count]).0
    }

    /// Perimeter of the core polygon, metres (twice the length for `count == 2`).
    pub fn core_perimeter(&self) -> Real {
        let n = self.count;
        (0..n)
            .map(|i| self.vertices[i].distance(self.vertices[(i + 1) % n]))
            .sum()
    }
}

/// Signed area and area centroid of a polygon (fan about its first vertex).
/// Returns the vertex average as centroid when the area is zero.
pub(crate) fn core_area_centroid(v: &[Vec2]) -> (Real, Vec2) {
    let n = v.len();
    if n == 0 {
        return (0.0, Vec2::ZERO);
    }
    let origin = v[0];
    let mut area = 0.0;
    let mut moment = Vec2::ZERO;
    for i in 1..n.saturating_sub(1) {
        let e1 = v[i] - origin;
        let e2 = v[i + 1] - origin;
        let a = 0.5 * cross(e1, e2);
        area += a;
        moment += a * (e1 + e2) / 3.0;
    }
    if area != 0.0 {
        (area, origin + moment / area)
    } else {
        let sum: Vec2 = v.iter().copied().sum();
        (0.0, sum / n as Real)
    }
}

/// Andrew's monotone chain: the strictly convex hull, counter-clockwise,
/// starting at the lowest-x (then lowest-y) point. Sorts `pts` in place.
fn monotone_chain(pts: &mut [Vec2]) -> Vec<Vec2> {
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let mut hull: Vec<Vec2> = Vec::with_capacity(pts.len() + 1);
    // Lower hull.
    for &p in pts.iter() {
        while hull.len() >= 2
            && cross(
                hull[hull.len() - 1] - hull[hull.len() - 2],
                p - hull[hull.len() - 2],
            ) <= 0.0
        {
            hull.pop();
        }
        hull.push(p);
    }
    // Upper hull.
    let lower_len = hull.len() + 1;
    for &p in pts.iter().rev().skip(1) {
        while hull.len() >= lower_len
            && cross(
                hull[hull.len() - 1] - hull[hull.len() - 2],
                p - hull[hull.len() - 2],
            ) <= 0.0
        {
            hull.pop();
        }
        hull.push(p);
    }
    // The last point repeats the first.
    hull.pop();
    hull
}

/// Drops hull vertices closer than [`WELD_DISTANCE`] to the line through their
/// neighbours, one at a time (the closest first), until none is left.
fn remove_collinear(hull: &mut Vec<Vec2>) {
    while hull.len() >= 3 {
        let n = hull.len();
        let mut worst = None;
        let mut worst_d = WELD_DISTANCE;
        for i in 0..n {
            let prev = hull[(i + n - 1) % n];
            let next = hull[(i + 1) % n];
            let base = next - prev;
            let len = base.length();
            let d = if len > EPSILON {
                cross(hull[i] - prev, base) / len
            } else {
                0.0
            };
            if d < worst_d {
                worst_d = d;
                worst = Some(i);
            }
        }
        match worst {
            Some(i) => {
                hull.remove(i);
            }
            None => break,
        }
    }
}

/// True when `n` is the unit vector `expected` within 1e-3 (a hand-built
/// polygon's normals are checked against its edges).
fn normal_matches(n: Vec2, expected: Vec2) -> bool {
    (n - expected).length() <= 1e-3
}

/// Any collision shape, in its body's local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)] // a Box would add an indirection to every collision
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Shape {
    /// A disc.
    Circle(Circle),
    /// A capsule.
    Capsule(Capsule),
    /// A convex (possibly rounded) polygon.
    Polygon(Polygon),
    /// A two-sided segment (no mass).
    Segment(Segment),
    /// A one-sided chain segment (no mass).
    ChainSegment(ChainSegment),
}

impl Shape {
    /// Checks a shape given by its public fields (a hand-built literal as
    /// much as a constructed one): finite coordinates, positive radii, and
    /// a polygon that is convex, counter-clockwise and has area, with unit
    /// outward normals and its centroid inside; a capsule core longer than
    /// [`WELD_DISTANCE`]; every coordinate and radius within
    /// [`MAX_EXTENT`](crate::limits::MAX_EXTENT).
    pub fn validate(&self) -> Result<(), GeometryError> {
        self.validate_form(WELD_DISTANCE)?;
        self.validate_extent()
    }

    /// [`validate`](Self::validate) for a shape the engine scaled (a portal
    /// clone's copy): segment, chain and capsule cores need only a
    /// non-zero length, since a valid core scaled by `η < 1` may be
    /// shorter than [`WELD_DISTANCE`].
    pub fn validate_scaled(&self) -> Result<(), GeometryError> {
        self.validate_form(0.0)?;
        self.validate_extent()
    }

    fn validate_extent(&self) -> Result<(), GeometryError> {
        let max = crate::limits::MAX_EXTENT;
        let small = |v: Real| v.abs() <= max;
        let ok = match self {
            Shape::Circle(c) => small(c.center.x) && small(c.center.y) && small(c.radius),
            Shape::Capsule(c) => {
                [c.center1, c.center2]
                    .iter()
                    .all(|p| small(p.x) && small(p.y))
                    && small(c.radius)
            }
            Shape::Segment(s) => [s.point1, s.point2]
                .iter()
                .all(|p| small(p.x) && small(p.y)),
            Shape::ChainSegment(c) => [c.ghost1, c.segment.point1, c.segment.point2, c.ghost2]
                .iter()
                .all(|p| small(p.x) && small(p.y)),
            Shape::Polygon(p) => {
                p.vertices[..p.count]
                    .iter()
                    .all(|v| small(v.x) && small(v.y))
                    && small(p.radius)
            }
        };
        if ok {
            Ok(())
        } else {
            Err(GeometryError::ExtentTooLarge { max })
        }
    }

    /// The checks of [`validate`](Self::validate) but the extent, with
    /// cores longer than `min_core`.
    fn validate_form(&self, min_core: Real) -> Result<(), GeometryError> {
        use GeometryError as E;
        let finite = |pts: &[Vec2]| pts.iter().all(|p| vec_is_finite(*p));
        match self {
            Shape::Circle(c) => {
                if !finite(&[c.center]) || !c.radius.is_finite() {
                    return Err(E::NonFinite);
                }
                if c.radius <= 0.0 {
                    return Err(E::NonPositiveRadius);
                }
            }
            Shape::Capsule(c) => {
                if !finite(&[c.center1, c.center2]) || !c.radius.is_finite() {
                    return Err(E::NonFinite);
                }
                if c.radius <= 0.0 {
                    return Err(E::NonPositiveRadius);
                }
                if (c.center2 - c.center1).length() <= min_core {
                    return Err(E::DegenerateSegment);
                }
            }
            Shape::Segment(s) => {
                if !finite(&[s.point1, s.point2]) {
                    return Err(E::NonFinite);
                }
                if (s.point2 - s.point1).length() <= min_core {
                    return Err(E::DegenerateSegment);
                }
            }
            Shape::ChainSegment(c) => {
                if !finite(&[c.ghost1, c.segment.point1, c.segment.point2, c.ghost2]) {
                    return Err(E::NonFinite);
                }
                if (c.segment.point2 - c.segment.point1).length() <= min_core {
                    return Err(E::DegenerateSegment);
                }
            }
            Shape::Polygon(p) => {
                let n = p.count;
                if n > MAX_POLYGON_VERTICES {
                    return Err(E::TooManyVertices { count: n });
                }
                if !finite(&p.vertices[..n])
                    || !finite(&p.normals[..n])
                    || !p.radius.is_finite()
                    || !vec_is_finite(p.centroid)
                {
                    return Err(E::NonFinite);
                }
                if p.radius < 0.0 {
                    return Err(E::NegativeRadius);
                }
                if n == 2 {
                    // A capsule core: needs a radius, a length and the two
                    // opposite side normals.
                    if p.radius <= 0.0 {
                        return Err(E::NonPositiveRadius);
                    }
                    let edge = p.vertices[1] - p.vertices[0];
                    if edge.length() <= min_core {
                        return Err(E::DegenerateSegment);
                    }
                    let side = right_perp(edge.normalize());
                    for (k, expected) in [(0, side), (1, -side)] {
                        if !normal_matches(p.normals[k], expected) {
                            return Err(E::BadNormal { edge: k });
                        }
                    }
                    return Ok(());
                }
                if n < 3 {
                    return Err(E::TooFewPoints {
                        found: n,
                        needed: 3,
                    });
                }
                // Twice the area, about the first vertex (not the origin:
                // a small polygon far from its body origin would lose the
                // area to rounding).
                let mut area2 = 0.0;
                let o = p.vertices[0];
                for i in 0..n {
                    let a = p.vertices[i];
                    let b = p.vertices[(i + 1) % n];
                    let c = p.vertices[(i + 2) % n];
                    if cross(b - a, c - b) <= 0.0 {
                        return Err(E::DegeneratePolygon);
                    }
                    area2 += cross(a - o, b - o);
                }
                if area2 <= 0.0 {
                    return Err(E::DegeneratePolygon);
                }
                for i in 0..n {
                    let edge = p.vertices[(i + 1) % n] - p.vertices[i];
                    let len = edge.length();
                    if len <= EPSILON {
                        return Err(E::DegeneratePolygon);
                    }
                    if !normal_matches(p.normals[i], right_perp(edge / len)) {
                        return Err(E::BadNormal { edge: i });
                    }
                }
                // The centroid (the centre of mass) lies inside the core,
                // with a tolerance of the weld distance plus the rounding of
                // coordinates this large (a sliver far out has its centroid
                // on an edge to within a few ulps).
                let scale = p.vertices[..n]
                    .iter()
                    .fold(p.centroid.abs().max_element(), |m, v| {
                        m.max(v.abs().max_element())
                    });
                let tolerance = WELD_DISTANCE + 16.0 * EPSILON * scale;
                for i in 0..n {
                    if p.normals[i].dot(p.centroid - p.vertices[i]) > tolerance {
                        return Err(E::CentroidOutside);
                    }
                }
            }
        }
        Ok(())
    }

    /// How far the shape reaches from its [`centroid`](Shape::centroid),
    /// metres: the radius of the smallest disc about the centroid that
    /// holds it (a polygon's farthest core vertex plus its rounding; half a
    /// capsule's or segment's length plus its radius).
    ///
    /// ```
    /// use janus2d_core::geometry::{Polygon, Shape};
    /// let square = Shape::Polygon(Polygon::make_box(0.3, 0.4));
    /// assert!((square.extent() - 0.5).abs() < 1e-6);
    /// ```
    #[must_use]
    pub fn extent(&self) -> Real {
        match self {
            Shape::Circle(c) => c.radius,
            Shape::Capsule(c) => 0.5 * (c.center2 - c.center1).length() + c.radius,
            Shape::Polygon(p) => {
                let far = p.vertices[..p.count]
                    .iter()
                    .map(|v| (*v - p.centroid).length())
                    .fold(0.0, Real::max);
                far + p.radius
            }
            Shape::Segment(s) => 0.5 * (s.point2 - s.point1).length(),
            Shape::ChainSegment(c) => 0.5 * (c.segment.point2 - c.segment.point1).length(),
        }
    }

    /// The geometric centre used for one-sided tests and as the centre of
    /// mass: circle centre, capsule/segment midpoint, polygon core centroid.
    pub fn centroid(&self) -> Vec2 {
        match self {
            Shape::Circle(c) => c.center,
            Shape::Capsule(c) => 0.5 * (c.center1 + c.center2),
            Shape::Polygon(p) => p.centroid,
            Shape::Segment(s) => 0.5 * (s.point1 + s.point2),
            Shape::ChainSegment(c) => 0.5 * (c.segment.point1 + c.segment.point2),
        }
    }
}

impl From<Circle> for Shape {
    fn from(v: Circle) -> Shape {
        Shape::Circle(v)
    }
}

impl From<Capsule> for Shape {
    fn from(v: Capsule) -> Shape {
        Shape::Capsule(v)
    }
}

impl From<Polygon> for Shape {
    fn from(v: Polygon) -> Shape {
        Shape::Polygon(v)
    }
}

impl From<Segment> for Shape {
    fn from(v: Segment) -> Shape {
        Shape::Segment(v)
    }
}

impl From<ChainSegment> for Shape {
    fn from(v: ChainSegment) -> Shape {
        Shape::ChainSegment(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: Real, y: Real) -> Vec2 {
        Vec2::new(x, y)
    }

    fn assert_valid_ccw(p: &Polygon) {
        let n = p.count;
        for i in 0..n {
            let a = p.vertices[i];
            let b = p.vertices[(i + 1) % n];
            let c = p.vertices[(i + 2) % n];
            assert!(cross(b - a, c - b) > 0.0, "not strictly convex CCW at {i}");
            assert!((p.normals[i].length() - 1.0).abs() < 1e-5);
            assert!(p.normals[i].dot(b - a).abs() < 1e-5);
            // Outward: the centroid is behind every edge.
            assert!(p.normals[i].dot(p.centroid - a) < 0.0);
        }
    }

    #[test]
    fn hull_of_square_with_interior_and_duplicate_points() {
        let pts = [
            v(1.0, 1.0),
            v(0.0, 0.0),
            v(-1.0, 1.0),
            v(0.3, -0.2),
            v(1.0, 1.0),
            v(-1.0, -1.0),
            v(1.0 + 0.001, 1.0),
            v(1.0, -1.0),
            v(0.0, 1.0), // on an edge: dropped as collinear
            v(-1.0, -1.0),
        ];
        let p = Polygon::from_hull(&pts, 0.0).unwrap();
        assert_eq!(p.count, 4);
        assert_valid_ccw(&p);
        assert!((p.core_area() - 4.0).abs() < 1e-5);
        assert!(p.centroid.length() < 1e-5);
        for corner in [v(1.0, 1.0), v(-1.0, 1.0), v(-1.0, -1.0), v(1.0, -1.0)] {
            assert!(p.vertices[..4].contains(&corner), "missing {corner:?}");
        }
    }

    #[test]
    fn hull_of_octagon_and_too_many_vertices() {
        let ring = |k: usize| -> Vec<Vec2> {
            (0..k)
                .map(|i| {
                    let a = crate::math::TAU * i as Real / k as Real;
                    v(a.cos(), a.sin())
                })
                .collect()
        };
        let p = Polygon::from_hull(&ring(8), 0.1).unwrap();
        assert_eq!(p.count, 8);
        assert_valid_ccw(&p);
        assert_eq!(
            Polygon::from_hull(&ring(9), 0.0),
            Err(GeometryError::TooManyVertices { count: 9 })
        );
    }

    #[test]
    fn hull_rejects_degenerate_input() {
        assert_eq!(
            Polygon::from_hull(&[], 0.0),
            Err(GeometryError::TooFewPoints {
                found: 0,
                needed: 3
            })
        );
        assert_eq!(
            Polygon::from_hull(&[v(0.0, 0.0), v(1.0, 0.0), v(1.0, 0.001)], 0.0),
            Err(GeometryError::TooFewPoints {
                found: 2,
                needed: 3
            })
        );
        assert_eq!(
            Polygon::from_hull(&[v(0.0, 0.0), v(1.0, 1.0), v(2.0, 2.0), v(3.0, 3.001)], 0.0),
            Err(GeometryError::CollinearPoints)
        );
        assert_eq!(
            Polygon::from_hull(&[v(0.0, 0.0), v(1.0, 0.0), v(Real::NAN, 1.0)], 0.0),
            Err(GeometryError::NonFinite)
        );
        assert_eq!(
            Polygon::from_hull(&[v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)], -0.1),
            Err(GeometryError::NegativeRadius)
        );
        assert_eq!(
            Polygon::from_hull(&[v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)], Real::INFINITY),
            Err(GeometryError::NonFinite)
        );
    }

    #[test]
    fn circle_capsule_segment_constructors_validate() {
        assert!(Circle::new(v(1.0, 2.0), 0.5).is_ok());
        assert_eq!(
            Circle::new(v(0.0, 0.0), 0.0),
            Err(GeometryError::NonPositiveRadius)
        );
        assert_eq!(
            Circle::new(v(0.0, 0.0), -1.0),
            Err(GeometryError::NonPositiveRadius)
        );
        assert_eq!(
            Circle::new(v(Real::NAN, 0.0), 1.0),
            Err(GeometryError::NonFinite)
        );
        assert!(Capsule::new(v(-1.0, 0.0), v(1.0, 0.0), 0.25).is_ok());
        assert_eq!(
            Capsule::new(v(0.0, 0.0), v(0.0, 0.0), 0.25),
            Err(GeometryError::DegenerateSegment)
        );
        assert_eq!(
            Capsule::new(v(0.0, 0.0), v(1.0, 0.0), 0.0),
            Err(GeometryError::NonPositiveRadius)
        );
        assert_eq!(
            Capsule::new(v(0.0, Real::INFINITY), v(1.0, 0.0), 1.0),
            Err(GeometryError::NonFinite)
        );
        assert_eq!(
            Segment::new(v(1.0, 1.0), v(1.0, 1.0)),
            Err(GeometryError::DegenerateSegment)
        );
        // Errors display and are std errors.
        let e: Box<dyn std::error::Error> = Box::new(GeometryError::TooManyVertices { count: 9 });
        assert!(e.to_string().contains('9'));
    }

    #[test]
    fn boxes_have_outward_unit_normals() {
        let b = Polygon::make_offset_box(1.0, 0.5, v(2.0, -1.0), 0.3);
        assert_eq!(b.count, 4);
        assert_valid_ccw(&b);
        assert!((b.centroid - v(2.0, -1.0)).length() < 1e-6);
        assert!((b.core_area() - 2.0).abs() < 1e-5);
        let r = Polygon::make_rounded_box(1.0, 1.0, 0.1);
        assert_eq!(r.radius, 0.1);
    }

    #[test]
    #[should_panic]
    fn make_box_panics_on_non_positive_extent() {
        let _ = Polygon::make_box(0.0, 1.0);
    }

    #[test]
    fn chain_builder_sets_ghosts() {
        let pts = [v(0.0, 0.0), v(1.0, 0.0), v(2.0, 0.5), v(3.0, 0.5)];
        let open = make_chain(&pts, false).unwrap();
        assert_eq!(open.len(), 3);
        assert_eq!(open[0].ghost1, pts[0]);
        assert_eq!(open[0].ghost2, pts[2]);
        assert_eq!(open[1].ghost1, pts[0]);
        assert_eq!(open[1].ghost2, pts[3]);
        assert_eq!(open[2].ghost2, pts[3]);
        // Front normal of a segment going +x points down (right-hand side).
        assert!((open[0].normal() - v(0.0, -1.0)).length() < 1e-6);

        let closed = make_chain(&pts, true).unwrap();
        assert_eq!(closed.len(), 4);
        assert_eq!(closed[0].ghost1, pts[3]);
        assert_eq!(closed[3].segment.point2, pts[0]);
        assert_eq!(closed[3].ghost2, pts[1]);

        assert_eq!(
            make_chain(&pts[..2], true),
            Err(GeometryError::TooFewPoints {
                found: 2,
                needed: 3
            })
        );
        assert_eq!(
            make_chain(&[v(0.0, 0.0), v(0.0, 0.0)], false),
            Err(GeometryError::DegenerateSegment)
        );
        assert_eq!(
            make_chain(&[v(0.0, 0.0), v(Real::NAN, 0.0)], false),
            Err(GeometryError::NonFinite)
        );
    }
}
