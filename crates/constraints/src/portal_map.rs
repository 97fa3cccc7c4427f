//! The portal map: where a point, a vector, an angle and a whole moving body
//! go when they pass from portal 1 to portal 2.
//!
//! # Derivation
//!
//! A [`Portal`] sits on a portal body (A for portal 1, B for portal 2). In
//! that body's frame it has an anchor `a`, a unit **outward** direction `d`
//! and a half-width `w`: the aperture is the segment of length `2 w` through
//! the anchor, perpendicular to `d`. A body enters portal 1 moving along
//! `−n1` and leaves portal 2 moving along `+n2`.
//!
//! In world space, with the portal body's angle `θ` and transform `X`, a
//! portal is a [`PortalFrame`]:
//!
//! ```text
//! P = X(a)            n = R(θ) d            t = perp(n)            α = atan2(n)
//! ```
//!
//! The [`PortalMap`] from side 1 to side 2 with scale `η > 0` is
//!
//! ```text
//! Q     = R(α2 − α1 + π)          (takes n1 to −n2 and t1 to −t2)
//! T(x)  = P2 + η Q (x − P1)       points
//! v ↦ η Q v                       vectors (displacements, velocities)
//! θ ↦ wrap(θ + α2 − α1 + π)       angles, wrap(x) = x − 2π round(x / 2π)
//! ```
//!
//! `Q` is built from the normals without trigonometry:
//! `cos(α2 − α1 + π) = −(n1 · n2)`, `sin(α2 − α1 + π) = −(n1 × n2)`.
//!
//! The portal constraint's position error, for a body at `(x1, θ1)` and its
//! clone at `(x2, θ2)` (`x` is always the centre of mass), with
//! `s1 = x1 − P1` and `s2 = x2 − P2`:
//!
//! ```text
//! c0 = η (s1 · n1) + (s2 · n2)
//! c1 = η (s1 × n1) + (s2 × n2)
//! c2 = wrap((θ1 − α1) − (θ2 − α2) − π)
//! ```
//!
//! `(c0, −c1)` are the components of `x2 − T(x1)` along `(n2, t2)`, so
//! `|(c0, c1)| = |x2 − T(x1)|` in world units on side 2.
//!
//! **Exact clone state.** A portal body moves with centre `x_A`, velocity
//! `v_A` and angular velocity `ω_A`; the portal frame is carried along, so
//! the velocity of a body relative to the moving frame is
//! `w1 = v1 − v_A − ω_A perp(x1 − x_A)`. The clone satisfies the constraint at
//! position and velocity level when
//!
//! ```text
//! x2 = T(x1)
//! θ2 = wrap(θ1 + α2 − α1 + π)
//! v2 = v_B + ω_B perp(x2 − x_B) + η Q (v1 − v_A − ω_A perp(x1 − x_A))
//! ω2 = ω1 − ω_A + ω_B
//! ```
//!
//! (`v2 − v_B − ω_B perp(x2 − x_B) = η Q w1` is exactly `ċ0 = ċ1 = 0`, and
//! `ω2 = ω1 − ω_A + ω_B` is `ċ2 = 0`.)
//!
//! ```
//! use janus2d_constraints::portal_map::{Portal, PortalPair};
//! use janus2d_core::math::{Transform, Vec2};
//!
//! // Portal 1 faces +x at the origin, portal 2 faces +y at (10, 0), twice as wide.
//! let a = Portal::new(Vec2::ZERO, Vec2::X, 1.0).unwrap();
//! let b = Portal::new(Vec2::new(10.0, 0.0), Vec2::Y, 2.0).unwrap();
//! let pair = PortalPair::from_apertures(a, b).unwrap();
//! assert!((pair.eta - 2.0).abs() < 1e-6);
//! let map = pair.map(&Transform::IDENTITY, &Transform::IDENTITY);
//! // A point 1 m in front of portal 1 (not yet through) maps 2 m behind
//! // portal 2, where the clone waits to come out.
//! let y = map.map_point(Vec2::new(1.0, 0.0));
//! assert!((y - Vec2::new(10.0, -2.0)).length() < 1e-5);
//! // Entering portal 1 (moving along −n1) means leaving portal 2 along +n2.
//! let v = map.map_vector(Vec2::new(-1.0, 0.0));
//! assert!((v - Vec2::new(0.0, 2.0)).length() < 1e-5);
//! ```

use janus2d_core::math::{Real, Rot, Transform, Vec2, cross, cross_sv, vec_is_finite, wrap_angle};

/// Invalid portal input at the API boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PortalError {
    /// The scale `η` is ≤ 0, NaN or infinite.
    InvalidScale,
    /// The scale `η` is finite and positive but outside
    /// [`ETA_MIN`, `ETA_MAX`]: beyond it a crossing's clone is so large or
    /// small against the original that the pair cannot be solved well
    /// (`η = 1e30` made the portal a hole; `η = 1e3` left a crossing hanging).
    ScaleOutOfRange,
    /// A portal direction is zero (or too short to normalise).
    ZeroDirection,
    /// A portal half-width is ≤ 0.
    NonPositiveHalfWidth,
    /// A value that must be finite is NaN or infinite (names the field).
    NonFinite(&'static str),
    /// Two roles of a portal constraint name the same body (the body and its
    /// clone, or a copy and a portal body it passes through).
    SameBody,
}

impl std::fmt::Display for PortalError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PortalError::InvalidScale => write!(f, "portal scale η must be finite and > 0"),
            PortalError::ScaleOutOfRange => {
                write!(f, "portal scale η must lie in [{ETA_MIN}, {ETA_MAX}]")
            }
            PortalError::ZeroDirection => write!(f, "portal direction must be non-zero"),
            PortalError::NonPositiveHalfWidth => write!(f, "portal half-width must be > 0"),
            PortalError::NonFinite(field) => write!(f, "portal field `{field}` is not finite"),
            PortalError::SameBody => write!(
                f,
                "a portal constraint needs distinct bodies for the body, its clone and the portal bodies they pass through"
            ),
        }
    }
}

impl std::error::Error for PortalError {}

/// Smallest portal scale `η` accepted (dimensionless): the clone of a body
/// is at least a hundredth of its size.
pub const ETA_MIN: Real = 1e-2;
/// Largest portal scale `η` accepted (dimensionless): the clone of a body
/// is at most a hundred times its size (`1/ETA_MIN`, so the inverse map of
/// an accepted pair is accepted too).
pub const ETA_MAX: Real = 1e2;

/// Checks a portal scale `η`: finite, > 0 ([`PortalError::InvalidScale`])
/// and within [`ETA_MIN`, `ETA_MAX`] ([`PortalError::ScaleOutOfRange`]).
///
/// ```
/// use janus2d_constraints::portal_map::{PortalError, validate_eta};
/// assert!(validate_eta(2.0).is_ok());
/// assert_eq!(validate_eta(-1.0), Err(PortalError::InvalidScale));
/// assert_eq!(validate_eta(1e3), Err(PortalError::ScaleOutOfRange));
/// ```
pub fn validate_eta(eta: Real) -> Result<(), PortalError> {
    if !(eta.is_finite() && eta > 0.0) {
        Err(PortalError::InvalidScale)
    } else if eta.max(1.0 / eta) > ETA_MAX * (1.0 + 16.0 * Real::EPSILON) {
        // Symmetric in η and 1/η (a pair is crossed both ways), with a few
        // ulps of room so that the inverse of an accepted scale passes.
        Err(PortalError::ScaleOutOfRange)
    } else {
        Ok(())
    }
}

/// A portal in its body's local frame.
///
/// Build it with [`Portal::new`], which validates the values and normalises
/// the direction. Code that fills the fields directly should call
/// [`Portal::validate`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Portal {
    /// Centre of the aperture in the body frame (relative to the body
    /// origin, like joint anchors), m.
    pub anchor: Vec2,
    /// Unit outward normal in the body frame (dimensionless): bodies enter
    /// along `−direction` and leave the other portal along its `+direction`.
    pub direction: Vec2,
    /// Half the aperture length, m (> 0).
    pub half_width: Real,
}

impl Portal {
    /// A validated portal; `direction` is normalised.
    ///
    /// ```
    /// use janus2d_constraints::portal_map::{Portal, PortalError};
    /// use janus2d_core::math::Vec2;
    /// let p = Portal::new(Vec2::ZERO, Vec2::new(0.0, 3.0), 0.5).unwrap();
    /// assert_eq!(p.direction, Vec2::Y);
    /// assert_eq!(Portal::new(Vec2::ZERO, Vec2::ZERO, 0.5), Err(PortalError::ZeroDirection));
    /// assert_eq!(Portal::new(Vec2::ZERO, Vec2::X, 0.0), Err(PortalError::NonPositiveHalfWidth));
    /// ```
    pub fn new(anchor: Vec2, direction: Vec2, half_width: Real) -> Result<Portal, PortalError> {
        let portal = Portal {
            anchor,
            direction,
            half_width,
        };
        portal.validate()?;
        Ok(Portal {
            direction: portal.unit_direction(),
            ..portal
        })
    }

    /// Checks the fields: finite, a non-zero direction, a half-width > 0.
    /// The direction need not be unit length here (it is normalised where
    /// it is used).
    pub fn validate(&self) -> Result<(), PortalError> {
        if !vec_is_finite(self.anchor) {
            return Err(PortalError::NonFinite("anchor"));
        }
        if !vec_is_finite(self.direction) {
            return Err(PortalError::NonFinite("direction"));
        }
        if !self.half_width.is_finite() {
            return Err(PortalError::NonFinite("half_width"));
        }
        if self.direction.try_normalize().is_none() {
            return Err(PortalError::ZeroDirection);
        }
        if self.half_width <= 0.0 {
            return Err(PortalError::NonPositiveHalfWidth);
        }
        Ok(())
    }

    /// The direction scaled to unit length (`+x` for an unvalidated zero
    /// direction, so that nothing downstream turns NaN).
    #[inline]
    pub fn unit_direction(&self) -> Vec2 {
        self.direction.try_normalize().unwrap_or(Vec2::X)
    }

    /// The same portal with its direction normalised.
    pub fn normalized(&self) -> Portal {
        Portal {
            direction: self.unit_direction(),
            ..*self
        }
    }
}

/// Two portals and the scale between them, in their bodies' local frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PortalPair {
    /// Portal 1, on portal body A.
    pub portal_a: Portal,
    /// Portal 2, on portal body B.
    pub portal_b: Portal,
    /// Scale `η` from portal 1 to portal 2 (dimensionless, > 0; usual 1).
    pub eta: Real,
}

impl PortalPair {
    /// A validated pair with an explicit scale.
    pub fn new(portal_a: Portal, portal_b: Portal, eta: Real) -> Result<PortalPair, PortalError> {
        portal_a.validate()?;
        portal_b.validate()?;
        validate_eta(eta)?;
        Ok(PortalPair {
            portal_a: portal_a.normalized(),
            portal_b: portal_b.normalized(),
            eta,
        })
    }

    /// A validated pair whose scale matches the apertures: `η = w_b / w_a`.
    pub fn from_apertures(portal_a: Portal, portal_b: Portal) -> Result<PortalPair, PortalError> {
        portal_a.validate()?;
        portal_b.validate()?;
        Self::new(
            portal_a,
            portal_b,
            portal_b.half_width / portal_a.half_width,
        )
    }

    /// The world-space map for the portal bodies' current transforms.
    pub fn map(&self, body_a: &Transform, body_b: &Transform) -> PortalMap {
        PortalMap {
            frame1: PortalFrame::new(body_a, &self.portal_a),
            frame2: PortalFrame::new(body_b, &self.portal_b),
            eta: self.eta,
        }
    }
}

/// A portal in world space: `(P, n, t, α)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PortalFrame {
    /// Centre of the aperture `P`, m.
    pub point: Vec2,
    /// Unit outward normal `n`.
    pub normal: Vec2,
    /// Unit tangent `t = perp(n)`.
    pub tangent: Vec2,
    /// Angle of the normal `α = atan2(n.y, n.x)`, rad (in `[−π, π]`; only its
    /// value modulo 2π matters).
    pub angle: Real,
}

impl PortalFrame {
    /// The world frame of `portal` on a body with transform `body` (body
    /// origin and rotation).
    pub fn new(body: &Transform, portal: &Portal) -> PortalFrame {
        Self::from_point_normal(
            body.apply(portal.anchor),
            body.q.rotate(portal.unit_direction()),
        )
    }

    /// A frame from a world point and a world normal (normalised here; `+x`
    /// if zero).
    pub fn from_point_normal(point: Vec2, normal: Vec2) -> PortalFrame {
        let normal = normal.try_normalize().unwrap_or(Vec2::X);
        PortalFrame {
            point,
            normal,
            tangent: normal.perp(),
            angle: normal.y.atan2(normal.x),
        }
    }
}

/// The motion of a portal body: the velocity field that carries its portal.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct PortalBodyMotion {
    /// Centre of mass `x_A`, m.
    pub center: Vec2,
    /// Velocity of the centre of mass `v_A`, m/s.
    pub linear_velocity: Vec2,
    /// Angular velocity `ω_A`, rad/s.
    pub angular_velocity: Real,
}

impl PortalBodyMotion {
    /// A portal body at rest (static, or a kinematic body not moving).
    pub const AT_REST: PortalBodyMotion = PortalBodyMotion {
        center: Vec2::ZERO,
        linear_velocity: Vec2::ZERO,
        angular_velocity: 0.0,
    };

    /// Velocity of the point `x` carried by the body: `v_A + ω_A perp(x − x_A)`.
    #[inline]
    pub fn velocity_at(&self, x: Vec2) -> Vec2 {
        self.linear_velocity + cross_sv(self.angular_velocity, x - self.center)
    }
}

/// Position, angle and velocities of a body, all about its centre of mass.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct BodyMotion {
    /// Centre of mass, m.
    pub center: Vec2,
    /// Angle, rad.
    pub angle: Real,
    /// Velocity of the centre of mass, m/s.
    pub linear_velocity: Vec2,
    /// Angular velocity, rad/s.
    pub angular_velocity: Real,
}

/// The map from portal 1 to portal 2 in world space.
///
/// Fields are public for inspection; [`PortalMap::new`] validates `eta`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PortalMap {
    /// Portal 1 (the side a body enters).
    pub frame1: PortalFrame,
    /// Portal 2 (the side the clone leaves).
    pub frame2: PortalFrame,
    /// Scale `η` (dimensionless, > 0).
    pub eta: Real,
}

impl PortalMap {
    /// A map between two world frames; `eta` must be finite and > 0.
    pub fn new(
        frame1: PortalFrame,
        frame2: PortalFrame,
        eta: Real,
    ) -> Result<PortalMap, PortalError> {
        validate_eta(eta)?;
        Ok(PortalMap {
            frame1,
            frame2,
            eta,
        })
    }

    /// The rotation `Q = R(α2 − α1 + π)`, which takes `n1` to `−n2`.
    #[inline]
    pub fn rotation(&self) -> Rot {
        let (n1, n2) = (self.frame1.normal, self.frame2.normal);
        Rot {
            c: -n1.dot(n2),
            s: -cross(n1, n2),
        }
    }

    /// `T(x) = P2 + η Q (x − P1)`.
    #[inline]
    pub fn map_point(&self, x: Vec2) -> Vec2 {
        self.frame2.point + self.map_vector(x - self.frame1.point)
    }

    /// `η Q v`: a displacement or a velocity relative to the portals.
    #[inline]
    pub fn map_vector(&self, v: Vec2) -> Vec2 {
        self.eta * self.rotation().rotate(v)
    }

    /// `Q v`: a direction (unscaled).
    #[inline]
    pub fn map_direction(&self, v: Vec2) -> Vec2 {
        self.rotation().rotate(v)
    }

    /// `wrap(θ + α2 − α1 + π)`.
    #[inline]
    pub fn map_angle(&self, angle: Real) -> Real {
        wrap_angle(angle + self.angle_offset())
    }

    /// `α2 − α1 + π`, wrapped into `[−π, π]`.
    #[inline]
    pub fn angle_offset(&self) -> Real {
        wrap_angle(self.frame2.angle - self.frame1.angle + janus2d_core::math::PI)
    }

    /// The map from portal 2 back to portal 1 (scale `1/η`).
    pub fn inverse(&self) -> PortalMap {
        PortalMap {
            frame1: self.frame2,
            frame2: self.frame1,
            eta: 1.0 / self.eta,
        }
    }

    /// The constraint's position error `(c0, c1, c2)` for a body at
    /// `(x1, θ1)` and its clone at `(x2, θ2)` (centres of mass).
    pub fn error(&self, x1: Vec2, angle1: Real, x2: Vec2, angle2: Real) -> [Real; 3] {
        let (f1, f2, eta) = (&self.frame1, &self.frame2, self.eta);
        let s1 = x1 - f1.point;
        let s2 = x2 - f2.point;
        [
            eta * s1.dot(f1.normal) + s2.dot(f2.normal),
            eta * cross(s1, f1.normal) + cross(s2, f2.normal),
            wrap_angle((angle1 - f1.angle) - (angle2 - f2.angle) - janus2d_core::math::PI),
        ]
    }

    /// The exact clone of `body`: the state that satisfies the constraint at
    /// position and velocity level while portal body A (carrying portal 1)
    /// and portal body B (carrying portal 2) move as given.
    ///
    /// ```
    /// use janus2d_constraints::portal_map::{BodyMotion, PortalBodyMotion, PortalFrame, PortalMap};
    /// use janus2d_core::math::Vec2;
    /// let f1 = PortalFrame::from_point_normal(Vec2::ZERO, Vec2::X);
    /// let f2 = PortalFrame::from_point_normal(Vec2::new(5.0, 0.0), Vec2::Y);
    /// let map = PortalMap::new(f1, f2, 1.0).unwrap();
    /// let body = BodyMotion {
    ///     center: Vec2::new(0.5, 0.0),
    ///     angle: 0.0,
    ///     linear_velocity: Vec2::new(-1.0, 0.0),
    ///     angular_velocity: 0.0,
    /// };
    /// let rest = PortalBodyMotion::AT_REST;
    /// let clone = map.clone_state(&body, &rest, &rest);
    /// assert!((clone.center - Vec2::new(5.0, -0.5)).length() < 1e-6);
    /// assert!((clone.linear_velocity - Vec2::new(0.0, 1.0)).length() < 1e-6);
    /// ```
    pub fn clone_state(
        &self,
        body: &BodyMotion,
        portal_body_a: &PortalBodyMotion,
        portal_body_b: &PortalBodyMotion,
    ) -> BodyMotion {
        let x1 = body.center;
        let x2 = self.map_point(x1);
        let w1 = body.linear_velocity - portal_body_a.velocity_at(x1);
        BodyMotion {
            center: x2,
            angle: self.map_angle(body.angle),
            linear_velocity: portal_body_b.velocity_at(x2) + self.map_vector(w1),
            angular_velocity: body.angular_velocity - portal_body_a.angular_velocity
                + portal_body_b.angular_velocity,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_are_typed() {
        let p = Portal::new(Vec2::ZERO, Vec2::X, 1.0).unwrap();
        assert_eq!(PortalPair::new(p, p, 0.0), Err(PortalError::InvalidScale));
        assert_eq!(PortalPair::new(p, p, -1.0), Err(PortalError::InvalidScale));
        assert_eq!(
            PortalPair::new(p, p, Real::NAN),
            Err(PortalError::InvalidScale)
        );
        assert_eq!(
            PortalPair::new(p, p, Real::INFINITY),
            Err(PortalError::InvalidScale)
        );
        for eta in [1e3, 1e30, 1e-3, 100.5, 0.0099] {
            assert_eq!(
                PortalPair::new(p, p, eta),
                Err(PortalError::ScaleOutOfRange),
                "η {eta}"
            );
        }
        for eta in [ETA_MIN, ETA_MAX, 1.0 / ETA_MIN, 1.0 / ETA_MAX, 1.0] {
            assert!(PortalPair::new(p, p, eta).is_ok(), "η {eta}");
        }
        assert_eq!(
            Portal::new(Vec2::new(Real::NAN, 0.0), Vec2::X, 1.0),
            Err(PortalError::NonFinite("anchor"))
        );
        assert_eq!(
            Portal::new(Vec2::ZERO, Vec2::X, Real::INFINITY),
            Err(PortalError::NonFinite("half_width"))
        );
        assert_eq!(
            Portal::new(Vec2::ZERO, Vec2::X, -1.0),
            Err(PortalError::NonPositiveHalfWidth)
        );
        let e: Box<dyn std::error::Error> = Box::new(PortalError::ZeroDirection);
        assert!(e.to_string().contains("direction"));
    }

    #[test]
    fn map_takes_n1_to_minus_n2_and_inverse_undoes_it() {
        let f1 = PortalFrame::from_point_normal(Vec2::new(1.0, 2.0), Vec2::new(0.6, 0.8));
        let f2 = PortalFrame::from_point_normal(Vec2::new(-3.0, 0.5), Vec2::new(-0.8, 0.6));
        let map = PortalMap::new(f1, f2, 2.5).unwrap();
        assert!((map.map_direction(f1.normal) + f2.normal).length() < 1e-6);
        assert!((map.map_direction(f1.tangent) + f2.tangent).length() < 1e-6);
        let x = Vec2::new(0.3, -0.7);
        let back = map.inverse().map_point(map.map_point(x));
        assert!((back - x).length() < 1e-5);
        let theta = 0.4;
        let back = map.inverse().map_angle(map.map_angle(theta));
        assert!(wrap_angle(back - theta).abs() < 1e-5);
    }
}
