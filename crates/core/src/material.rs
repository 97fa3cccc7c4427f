//! Surface materials: how the friction and restitution of two touching
//! shapes combine into their contact's (Box2D v3's default rules).
//!
//! | property    | rule              | why                                        |
//! |-------------|-------------------|--------------------------------------------|
//! | friction    | `√(μ_a μ_b)`      | ice on anything stays slippery             |
//! | restitution | `max(e_a, e_b)`   | a bouncy ball bounces on any floor         |

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
