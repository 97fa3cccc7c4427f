//! Axis-aligned bounding boxes.

use crate::math::{Real, Vec2};

/// An axis-aligned bounding box given by its lower and upper corners.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Aabb {
    /// Lower corner (minimum x and y).
    pub lower: Vec2,
    /// Upper corner (maximum x and y).
    pub upper: Vec2,
}

impl Aabb {
    /// A box from its two corners.
    #[inline]
    pub fn new(lower: Vec2, upper: Vec2) -> Self {
        Aabb { lower, upper }
    }

    /// True when the two boxes overlap (touching counts).
    #[inline(always)]
    pub fn overlaps(&self, other: &Aabb) -> bool {
        !(other.lower.x > self.upper.x
            || other.lower.y > self.upper.y
            || self.lower.x > other.upper.x
            || self.lower.y > other.upper.y)
    }

    /// True when `self` contains `other` entirely.
    #[inline]
    pub fn contains(&self, other: &Aabb) -> bool {
        self.lower.x <= other.lower.x
            && self.lower.y <= other.lower.y
            && other.upper.x <= self.upper.x
            && other.upper.y <= self.upper.y
    }

    /// The smallest box holding both.
    #[inline]
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            lower: self.lower.min(other.lower),
            upper: self.upper.max(other.upper),
        }
    }

    /// The box grown by `margin` on every side.
    #[inline]
    pub fn fattened(&self, margin: Real) -> Aabb {
        let m = Vec2::splat(margin);
        Aabb {
            lower: self.lower - m,
            upper: self.upper + m,
        }
    }

    /// Perimeter (the surface-area heuristic's cost in 2D).
    #[inline]
    pub fn perimeter(&self) -> Real {
        2.0 * ((self.upper.x - self.lower.x) + (self.upper.y - self.lower.y))
    }

    /// The largest distance from `point` to a corner of the box, m: no
    /// point inside the box lies farther from `point` (a shape's reach
    /// from its body's centre or origin, what a turn of the body sweeps).
    ///
    /// ```
    /// use janus2d_core::geometry::Aabb;
    /// use janus2d_core::math::Vec2;
    /// let b = Aabb::new(Vec2::new(-1.0, 0.0), Vec2::new(3.0, 2.0));
    /// assert_eq!(b.reach_from(Vec2::ZERO), Vec2::new(3.0, 2.0).length());
    /// ```
    #[inline]
    #[must_use]
    pub fn reach_from(&self, point: Vec2) -> Real {
        (self.lower - point)
            .abs()
            .max((self.upper - point).abs())
            .length()
    }

    /// Centre of the box.
    #[inline]
    pub fn center(&self) -> Vec2 {
        0.5 * (self.lower + self.upper)
    }

    /// True when the corners are finite and ordered.
    pub fn is_valid(&self) -> bool {
        self.lower.x.is_finite()
            && self.lower.y.is_finite()
            && self.upper.x.is_finite()
            && self.upper.y.is_finite()
            && self.lower.x <= self.upper.x
            && self.lower.y <= self.upper.y
    }
}
