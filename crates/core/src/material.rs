//! Surface materials: how the friction and restitution of two touching
//! shapes combine into their contact's, and the surface terms a contact
//! takes from its shapes (rolling resistance, tangent speed).
//!
//! | property           | default rule        | why                                     |
//! |--------------------|---------------------|-----------------------------------------|
//! | friction           | `√(μ_a μ_b)`        | ice on anything stays slippery (Box2D)  |
//! | restitution        | `max(e_a, e_b)`     | a bouncy ball bounces on any floor      |
//! | rolling resistance | `max(c_a, c_b) · r` | `r`: the larger rolling radius          |
//! | tangent speed      | `s_a + s_b`         | both surfaces move (conveyor belts)     |
//!
//! A shape may ask for another friction or restitution rule
//! ([`CombineRule`], Rapier's `CoefficientCombineRule`): where the two
//! shapes ask for different rules, the stronger one wins, in the order
//! `Default < Average < Min < Multiply < Max` ([`combine`]).

use crate::math::Real;

/// Mixes two friction coefficients: `√(μ_a μ_b)`.
#[inline]
#[must_use]
pub fn mix_friction(a: Real, b: Real) -> Real {
    (a * b).sqrt()
}

/// Mixes two restitution coefficients: `max(e_a, e_b)`.
#[inline]
#[must_use]
pub fn mix_restitution(a: Real, b: Real) -> Real {
    a.max(b)
}

/// How a shape's friction or restitution combines with the other shape's
/// at a contact (Rapier's `CoefficientCombineRule`, with Box2D's rules as
/// the default).
///
/// Each shape names a rule per property; the contact uses the stronger of
/// the two, in declaration order (`Default` the weakest, `Max` the
/// strongest), so one shape that asks for `Max` restitution bounces off
/// every default surface.
///
/// ```
/// use janus2d_core::material::{CombineRule, Property, combine};
/// let f = |rule| combine(Property::Friction, 0.2, rule, 0.8, CombineRule::Default);
/// assert!((f(CombineRule::Default) - 0.4).abs() < 1e-6); // √(0.2 · 0.8)
/// assert!((f(CombineRule::Average) - 0.5).abs() < 1e-6);
/// assert!((f(CombineRule::Min) - 0.2).abs() < 1e-6);
/// assert!((f(CombineRule::Multiply) - 0.16).abs() < 1e-6);
/// assert!((f(CombineRule::Max) - 0.8).abs() < 1e-6);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum CombineRule {
    /// The property's default rule: `√(a b)` for friction (Box2D),
    /// `max(a, b)` for restitution. The weakest: any other rule of the
    /// other shape wins.
    #[default]
    Default,
    /// `(a + b) / 2`.
    Average,
    /// `min(a, b)`.
    Min,
    /// `a · b`.
    Multiply,
    /// `max(a, b)`.
    Max,
}

/// Which coefficient [`combine`] mixes (it names the default rule).
///
/// ```
/// use janus2d_core::material::{CombineRule, Property, combine};
/// // The same rules, the property's default: friction √(a b), restitution max.
/// let (r, d) = (CombineRule::Default, CombineRule::Default);
/// assert_eq!(combine(Property::Friction, 0.25, r, 1.0, d), 0.5);
/// assert_eq!(combine(Property::Restitution, 0.25, r, 1.0, d), 1.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Property {
    /// Friction: default `√(a b)`.
    Friction,
    /// Restitution: default `max(a, b)`.
    Restitution,
}

/// Mixes the coefficients `a` and `b` of two shapes whose rules are
/// `rule_a` and `rule_b`: the stronger rule ([`CombineRule`]) applies.
///
/// ```
/// use janus2d_core::material::{CombineRule, Property, combine};
/// // Restitution's default is the larger value.
/// let e = combine(Property::Restitution, 0.1, CombineRule::Default, 0.5, CombineRule::Default);
/// assert_eq!(e, 0.5);
/// // A `Min` shape against a default one: `Min` is the stronger rule.
/// let e = combine(Property::Restitution, 0.1, CombineRule::Min, 0.5, CombineRule::Default);
/// assert_eq!(e, 0.1);
/// ```
#[inline]
#[must_use]
pub fn combine(
    property: Property,
    a: Real,
    rule_a: CombineRule,
    b: Real,
    rule_b: CombineRule,
) -> Real {
    match rule_a.max(rule_b) {
        CombineRule::Default => match property {
            Property::Friction => mix_friction(a, b),
            Property::Restitution => mix_restitution(a, b),
        },
        CombineRule::Average => 0.5 * (a + b),
        CombineRule::Min => a.min(b),
        CombineRule::Multiply => a * b,
        CombineRule::Max => a.max(b),
    }
}

/// Mixes two rolling resistances into the bound of a contact's rolling
/// row per unit normal impulse, m: `max(c_a, c_b) · max(r_a, r_b)`, with
/// `r` the rolling radius of each shape (a circle's or a capsule's radius,
/// a rounded polygon's rounding, 0 for other shapes). 0 when neither shape
/// resists rolling.
///
/// ```
/// use janus2d_core::material::mix_rolling_resistance;
/// assert_eq!(mix_rolling_resistance(0.1, 0.5, 0.0, 0.0), 0.05);
/// assert_eq!(mix_rolling_resistance(0.0, 0.5, 0.0, 0.0), 0.0);
/// ```
#[inline]
#[must_use]
pub fn mix_rolling_resistance(c_a: Real, r_a: Real, c_b: Real, r_b: Real) -> Real {
    let c = c_a.max(c_b);
    if c > 0.0 { c * r_a.max(r_b) } else { 0.0 }
}

/// Mixes two tangent speeds into a contact's, m/s: `s_a + s_b` (see
/// `ShapeDef::tangent_speed`: each shape's surface moves at its speed
/// clockwise around the shape, so along the contact's tangent
/// `t = (n.y, −n.x)` shape a's surface moves at `s_a` and shape b's at
/// `−s_b`; the friction rows drive the relative tangent speed of the
/// bodies at the points to `s_a + s_b`).
///
/// ```
/// use janus2d_core::material::mix_tangent_speed;
/// assert_eq!(mix_tangent_speed(2.0, 0.0), 2.0);
/// ```
#[inline]
#[must_use]
pub fn mix_tangent_speed(s_a: Real, s_b: Real) -> Real {
    s_a + s_b
}
