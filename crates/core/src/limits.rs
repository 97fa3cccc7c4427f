//! The stated finite ranges of every value the API accepts.
//!
//! A value outside its range is a typed error naming the field and the
//! limit (`OutOfBounds { field, min, max }`), never a silent clamp, with
//! one exception: mass properties *computed from shapes* are clamped into
//! [`MASS_RANGE`] and [`INERTIA_RANGE`] (a directly given mass is checked).
//! The ranges are far beyond anything a simulation needs; they exist so
//! that no sum, product or inverse the engine forms can overflow.
//!
//! | limit                   | value              | applies to                                             |
//! |-------------------------|--------------------|--------------------------------------------------------|
//! | [`MAX_COORDINATE`]      | 1e9 m              | body positions, teleports, targets; a pose beyond twice it after a step is reset and reported (f32 resolves 1 mm only within 16,384 m: see below) |
//! | [`MAX_EXTENT`]          | 1e7 m              | shape coordinates and radii (body frame)               |
//! | [`MASS_RANGE`]          | 1e-12 … 1e15 kg    | the mass of a dynamic body                             |
//! | [`INERTIA_RANGE`]       | 1e-20 … 1e25 kg·m² | the rotational inertia of a dynamic, rotating body     |
//! | [`MAX_SPEED`]           | 1e9 m/s            | velocities given, `max_linear_speed`                    |
//! | [`MAX_ANGULAR_SPEED`]   | 1e9 rad/s          | angular velocities given                               |
//! | [`MAX_GRAVITY`]         | 1e6 m/s²           | the length of world gravity                            |
//! | [`MAX_GRAVITY_SCALE`]   | 1e6                | the magnitude of a body's gravity scale                |
//! | [`MAX_DAMPING_RATIO`]   | 1e4                | contact and joint damping ratios                        |
//! | [`MAX_FRICTION`]        | 1e6                | a shape's friction coefficient                         |
//! | [`MAX_RESTITUTION`]     | 1e3                | a shape's restitution                                  |
//! | [`ETA_RANGE`]           | 1e-2 … 1e2         | a portal pair's scale η (a clone's mass goes as η², its inertia as η⁴) |
//! | [`MAX_HERTZ_FRACTION`]  | 0.25               | contact and iterative joint stiffness are capped at this fraction of the substep rate, as Box2D caps them |
//! | [`UNIT_ROTATION_TOLERANCE`] | 1e-3           | how far `c² + s²` of a rotation given to the API may be from 1 |
//! | [`TIME_STEP_RANGE`]     | 1e-6 … 1 s         | the `dt` of a step                                     |
//!
//! # Coordinate resolution
//!
//! [`MAX_COORDINATE`] bounds what the API accepts, not where a world stays
//! precise. A coordinate `x` is stored to the spacing of its floating-point
//! type at `|x|` (`2^(k−23)` m in f32, `2^(k−52)` m in f64, for `|x|` in
//! `[2^k, 2^(k+1))`), and rounded to half of it:
//!
//! | `|x|` up to        | f32 spacing | f64 spacing |
//! |--------------------|-------------|-------------|
//! | 1,024 m            | 0.06 mm     | 1.1e-13 m   |
//! | **16,384 m** (2^14) | **0.98 mm** | 1.8e-12 m   |
//! | 131,072 m (2^17)   | 7.8 mm      | 1.5e-11 m   |
//! | 1,048,576 m (2^20) | 6.3 cm      | 1.2e-10 m   |
//! | 1.07e9 m (2^30; [`MAX_COORDINATE`] is 1e9) | 64 m | 1.2e-7 m |
//!
//! **f32 resolves 1 mm up to 16 km from the origin**: keep an f32 world's
//! bodies within ±16,384 m (its contacts' 5 mm `LINEAR_SLOP` and a 0.1 m broadphase
//! margin are resolved well inside that). Beyond it positions, contact
//! points and joint anchors snap to coarser steps: a body only moves when
//! its step `v · dt` exceeds half the spacing (at 4e8 m, where the spacing
//! is 32 m, a body at 400 m/s moves 6.7 m per 1/60 s step and stays where it
//! is). **For larger worlds build with the `f64` feature**: its spacing is
//! under a micrometre everywhere up to [`MAX_COORDINATE`] (0.12 µm at
//! 1e9 m). The limit itself is the same in both builds, so that no sum or
//! product the engine forms overflows; moving a world's origin (shifting
//! every body) is the other answer, outside the engine.

use crate::math::Real;

pub use crate::math::UNIT_ROTATION_TOLERANCE;

/// Allowed time step of `World::step(dt)`, s: `[1e-6, 1]`.
///
/// The upper bound: a step is one explicit integration and one
/// sleep-timer increment; at a second per step gravity alone moves a body
/// 10 m between collision checks, and a longer step would put a swinging
/// body to sleep in one step (its sleep timer gaining `dt`). Simulate a
/// longer span as several steps. The lower bound keeps the substep rate
/// (`substeps / dt`, up to 1024 substeps) and every force read back from
/// an impulse (`impulse / h`) finite: at `f32::MIN_POSITIVE` they were ∞.
pub const TIME_STEP_RANGE: (Real, Real) = (1e-6, 1.0);

/// Largest magnitude of a body coordinate, m (1e9): what the API accepts,
/// so that no sum or product the engine forms overflows. Precision is
/// another matter: f32 resolves 1 mm only up to 16,384 m from the origin
/// (64 m spacing near this limit); build with the `f64` feature for larger
/// worlds (0.12 µm spacing at 1e9 m). See the module's "Coordinate
/// resolution".
pub const MAX_COORDINATE: Real = 1e9;

/// Largest magnitude of a shape coordinate or radius in its body's frame,
/// m (1e7).
pub const MAX_EXTENT: Real = 1e7;

/// Allowed mass of a dynamic body, kg: `[1e-12, 1e15]`.
pub const MASS_RANGE: (Real, Real) = (1e-12, 1e15);

/// Allowed rotational inertia of a dynamic rotating body, kg·m²:
/// `[1e-20, 1e25]`.
pub const INERTIA_RANGE: (Real, Real) = (1e-20, 1e25);

/// Largest linear speed a body may be given (and largest
/// `max_linear_speed`), m/s (1e9).
pub const MAX_SPEED: Real = 1e9;

/// Largest angular speed a body may be given, rad/s (1e9).
pub const MAX_ANGULAR_SPEED: Real = 1e9;

/// Largest length of world gravity, m/s² (1e6).
pub const MAX_GRAVITY: Real = 1e6;

/// Largest magnitude of a body's gravity scale (1e6).
pub const MAX_GRAVITY_SCALE: Real = 1e6;

/// Largest contact or joint damping ratio (1e4).
pub const MAX_DAMPING_RATIO: Real = 1e4;

/// Largest joint spring stiffness, Hz (1e6: a stiffer spring's softness
/// overflows).
pub const MAX_SPRING_HERTZ: Real = 1e6;

/// Largest friction coefficient of a shape (1e6: the friction impulse
/// bound `μ λ_n` must stay finite).
pub const MAX_FRICTION: Real = 1e6;

/// Largest restitution of a shape (1e3).
pub const MAX_RESTITUTION: Real = 1e3;

/// Allowed scale η of a portal pair: `[1e-2, 1e2]` (the portal map's
/// `ETA_MIN` and `ETA_MAX`).
pub const ETA_RANGE: (Real, Real) = (1e-2, 1e2);

/// Contact stiffness and iterative joint stiffness are capped at this
/// fraction of the substep rate `1 / h` (0.25, as Box2D caps
/// `contactHertz`): stiffer soft rows cannot be resolved by the substeps.
pub const MAX_HERTZ_FRACTION: Real = 0.25;

/// True when `v` is finite and `|v| ≤ max`.
#[inline]
#[must_use]
pub fn within(v: Real, max: Real) -> bool {
    v.is_finite() && v.abs() <= max
}

/// True when `v` is finite and in `[range.0, range.1]`.
#[inline]
#[must_use]
pub fn in_range(v: Real, range: (Real, Real)) -> bool {
    v.is_finite() && v >= range.0 && v <= range.1
}

/// `v` clamped into `range` (NaN gives the lower end).
#[inline]
#[must_use]
pub fn clamp_to(v: Real, range: (Real, Real)) -> Real {
    if v.is_nan() {
        range.0
    } else {
        v.clamp(range.0, range.1)
    }
}
