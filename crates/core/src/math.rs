//! Scalar, vector, rotation and transform types shared by the whole engine.
//!
//! | build            | [`Real`] | [`Vec2`]          |
//! |------------------|----------|-------------------|
//! | default          | `f32`    | `glam::Vec2`      |
//! | feature `f64`    | `f64`    | `glam::DVec2`     |
//!
//! Conventions (the same as the portal spec (docs/portal.md)):
//! - 2D cross product `a × b = a.x*b.y - a.y*b.x` is [`cross`] (glam: `perp_dot`);
//! - `perp(v) = (-v.y, v.x)`, so `ω × v = ω * perp(v)` is [`cross_sv`];
//! - a [`Rot`] stores cosine and sine, never the angle.

/// The engine's one scalar type: `f32`, or `f64` with the `f64` feature.
#[cfg(not(feature = "f64"))]
pub type Real = f32;
/// The engine's one scalar type: `f32`, or `f64` with the `f64` feature.
#[cfg(feature = "f64")]
pub type Real = f64;

/// The engine's 2D vector: `glam::Vec2`, or `glam::DVec2` with the `f64` feature.
#[cfg(not(feature = "f64"))]
pub type Vec2 = glam::Vec2;
/// The engine's 2D vector: `glam::Vec2`, or `glam::DVec2` with the `f64` feature.
#[cfg(feature = "f64")]
pub type Vec2 = glam::DVec2;

/// `x` as f64 in both builds (the identity with the `f64` feature): for
/// work that needs the extra digits whatever [`Real`] is, and for reports.
#[inline(always)]
#[allow(clippy::useless_conversion)]
pub fn to_f64(x: Real) -> f64 {
    f64::from(x)
}

/// An f64 rounded to [`Real`] (the identity with the `f64` feature).
#[inline(always)]
#[allow(clippy::unnecessary_cast)]
pub fn from_f64(x: f64) -> Real {
    x as Real
}

/// π in the engine's precision.
#[cfg(not(feature = "f64"))]
pub const PI: Real = std::f32::consts::PI;
/// π in the engine's precision.
#[cfg(feature = "f64")]
pub const PI: Real = std::f64::consts::PI;

/// 2π in the engine's precision.
pub const TAU: Real = 2.0 * PI;

/// Machine epsilon of [`Real`].
pub const EPSILON: Real = Real::EPSILON;

/// 2D cross product of two vectors, `a.x*b.y - a.y*b.x` (a scalar).
#[inline(always)]
pub fn cross(a: Vec2, b: Vec2) -> Real {
    a.x * b.y - a.y * b.x
}

/// Cross product of a scalar (an angular velocity) and a vector: `s * perp(v)`.
#[inline(always)]
pub fn cross_sv(s: Real, v: Vec2) -> Vec2 {
    Vec2::new(-s * v.y, s * v.x)
}

/// Cross product of a vector and a scalar: `-s * perp(v)`.
#[inline(always)]
pub fn cross_vs(v: Vec2, s: Real) -> Vec2 {
    Vec2::new(s * v.y, -s * v.x)
}

/// Wraps an angle into `[-π, π]`: `x - 2π round(x / 2π)`.
///
/// Inside half a turn (`|x| < π`, nearly every angle the solver wraps) it
/// is `x` after one comparison: `|x| < π` holds exactly when the rounded
/// `|x / 2π|` is below ½, since `2π` is `π` doubled exactly and the largest
/// float below `π` divides to the float just below ½. Within one turn either
/// way (`|x / 2π| < 1.5`) the rounding is two comparisons, bit for bit the
/// same result as `round` (half away from zero) without its library call.
#[inline]
pub fn wrap_angle(x: Real) -> Real {
    if x.abs() < PI {
        // No division on the common path (every joint angle read).
        return x;
    }
    let k = x / TAU;
    if k.abs() < 1.5 {
        if k >= 0.5 {
            x - TAU
        } else if k <= -0.5 {
            x + TAU
        } else {
            x
        }
    } else {
        x - TAU * k.round()
    }
}

/// True when every component is finite.
#[inline]
pub fn vec_is_finite(v: Vec2) -> bool {
    v.x.is_finite() && v.y.is_finite()
}

/// How far `c² + s²` of a rotation may be from 1 (1e-3): a body's stored
/// rotation, and a rotation the API takes (query transforms, kinematic
/// targets), which is normalised within this tolerance and refused
/// outside it (see [`Rot::is_unit`]). Listed with the other limits in
/// [`crate::limits`].
pub const UNIT_ROTATION_TOLERANCE: Real = 1e-3;

/// A rotation stored as cosine and sine (unit length).
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(C)]
pub struct Rot {
    /// Cosine of the angle.
    pub c: Real,
    /// Sine of the angle.
    pub s: Real,
}

impl Default for Rot {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Rot {
    /// No rotation.
    pub const IDENTITY: Rot = Rot { c: 1.0, s: 0.0 };

    /// The rotation by `angle` radians.
    #[inline]
    pub fn from_angle(angle: Real) -> Self {
        let (s, c) = angle.sin_cos();
        Rot { c, s }
    }

    /// The angle in `[-π, π]`.
    #[inline]
    pub fn angle(self) -> Real {
        self.s.atan2(self.c)
    }

    /// Rotates a vector.
    #[inline(always)]
    pub fn rotate(self, v: Vec2) -> Vec2 {
        Vec2::new(self.c * v.x - self.s * v.y, self.s * v.x + self.c * v.y)
    }

    /// Rotates a vector by the inverse rotation.
    #[inline(always)]
    pub fn inv_rotate(self, v: Vec2) -> Vec2 {
        Vec2::new(self.c * v.x + self.s * v.y, -self.s * v.x + self.c * v.y)
    }

    /// `self * other`: apply `other`, then `self`.
    #[inline(always)]
    #[allow(clippy::should_implement_trait)]
    pub fn mul(self, other: Rot) -> Rot {
        Rot {
            c: self.c * other.c - self.s * other.s,
            s: self.s * other.c + self.c * other.s,
        }
    }

    /// `self⁻¹ * other`: the rotation from `self` to `other`.
    #[inline(always)]
    pub fn inv_mul(self, other: Rot) -> Rot {
        Rot {
            c: self.c * other.c + self.s * other.s,
            s: self.c * other.s - self.s * other.c,
        }
    }

    /// The relative angle from `self` to `other`, in `[-π, π]`: what the
    /// joints' angle rows read every iteration, through [`solver_atan2`]
    /// (within 3.0e-7 rad of the true angle in the f32 build, `f64::atan2`
    /// in the f64 build).
    #[inline]
    pub fn relative_angle(self, other: Rot) -> Real {
        let q = self.inv_mul(other);
        solver_atan2(q.s, q.c)
    }

    /// Normalises to unit length (identity if degenerate).
    #[inline]
    pub fn normalize(self) -> Rot {
        let mag = (self.c * self.c + self.s * self.s).sqrt();
        if mag > EPSILON {
            let inv = 1.0 / mag;
            Rot {
                c: self.c * inv,
                s: self.s * inv,
            }
        } else {
            Rot::IDENTITY
        }
    }

    /// Advances the rotation by an angle increment `h * w` (first-order, then
    /// normalised), as Box2D v3 integrates rotations.
    #[inline(always)]
    pub fn integrate(self, delta_angle: Real) -> Rot {
        Rot {
            c: self.c - delta_angle * self.s,
            s: self.s + delta_angle * self.c,
        }
        .normalize()
    }

    /// The unit x axis of the rotated frame.
    #[inline]
    pub fn x_axis(self) -> Vec2 {
        Vec2::new(self.c, self.s)
    }

    /// True when both components are finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.c.is_finite() && self.s.is_finite()
    }

    /// True when `c² + s²` is within
    /// [`UNIT_ROTATION_TOLERANCE`]
    /// of 1 (a rotation, not a scaling).
    ///
    /// ```
    /// use janus2d_core::math::Rot;
    /// assert!(Rot::from_angle(0.7).is_unit());
    /// assert!(!Rot { c: 2.0, s: 0.0 }.is_unit());
    /// ```
    #[inline]
    pub fn is_unit(self) -> bool {
        let m = self.c * self.c + self.s * self.s;
        (m - 1.0).abs() <= UNIT_ROTATION_TOLERANCE
    }

    /// The rotation normalised to unit length when it
    /// [`is_unit`](Self::is_unit) (within the tolerance), `None` otherwise
    /// (a scaling, a zero, a NaN or a component whose square overflows):
    /// how the API takes a rotation.
    ///
    /// ```
    /// use janus2d_core::math::Rot;
    /// let q = Rot { c: 0.9995, s: 0.0 }.to_unit().unwrap();
    /// assert!((q.c - 1.0).abs() < 1e-6 && q.s == 0.0);
    /// assert_eq!(Rot { c: 1e20, s: 1e20 }.to_unit(), None);
    /// assert_eq!(Rot { c: 0.0, s: 0.0 }.to_unit(), None);
    /// ```
    #[inline]
    pub fn to_unit(self) -> Option<Rot> {
        self.is_unit().then(|| self.normalize())
    }
}

/// A rigid transform: rotation then translation.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Transform {
    /// Translation (the body origin in world space).
    pub p: Vec2,
    /// Rotation.
    pub q: Rot,
}

impl Transform {
    /// The identity transform.
    pub const IDENTITY: Transform = Transform {
        p: Vec2::ZERO,
        q: Rot::IDENTITY,
    };

    /// A transform from a position and an angle.
    pub fn new(p: Vec2, angle: Real) -> Self {
        Transform {
            p,
            q: Rot::from_angle(angle),
        }
    }

    /// Maps a local point to world space.
    #[inline(always)]
    pub fn apply(&self, v: Vec2) -> Vec2 {
        self.q.rotate(v) + self.p
    }

    /// Maps a world point to local space.
    #[inline(always)]
    pub fn apply_inv(&self, v: Vec2) -> Vec2 {
        self.q.inv_rotate(v - self.p)
    }

    /// `self * other` (apply `other`, then `self`).
    #[inline]
    #[allow(clippy::should_implement_trait)]
    pub fn mul(&self, other: &Transform) -> Transform {
        Transform {
            q: self.q.mul(other.q),
            p: self.q.rotate(other.p) + self.p,
        }
    }

    /// `self⁻¹ * other`: `other` expressed in the frame of `self`.
    #[inline]
    pub fn inv_mul(&self, other: &Transform) -> Transform {
        Transform {
            q: self.q.inv_mul(other.q),
            p: self.q.inv_rotate(other.p - self.p),
        }
    }
}

impl std::ops::Mul for Rot {
    type Output = Rot;
    /// `q * r`: rotate by `r`, then by `q` (same as [`Rot::mul`]).
    ///
    /// ```
    /// use janus2d_core::math::Rot;
    /// let q = Rot::from_angle(0.25) * Rot::from_angle(0.5);
    /// assert!((q.angle() - 0.75).abs() < 1e-6);
    /// ```
    #[inline]
    fn mul(self, other: Rot) -> Rot {
        Rot::mul(self, other)
    }
}

impl std::ops::Mul<crate::math::Vec2> for Rot {
    type Output = Vec2;
    /// Rotates a vector (same as [`Rot::rotate`]).
    #[inline]
    fn mul(self, v: Vec2) -> Vec2 {
        self.rotate(v)
    }
}

impl std::ops::Mul for Transform {
    type Output = Transform;
    /// `a * b`: apply `b`, then `a` (same as [`Transform::mul`]).
    ///
    /// ```
    /// use janus2d_core::math::{Transform, Vec2};
    /// let a = Transform::new(Vec2::new(1.0, 0.0), 0.0);
    /// let b = Transform::new(Vec2::new(0.0, 2.0), 0.0);
    /// assert_eq!((a * b).p, Vec2::new(1.0, 2.0));
    /// ```
    #[inline]
    fn mul(self, other: Transform) -> Transform {
        Transform::mul(&self, &other)
    }
}

impl std::ops::Mul<Vec2> for Transform {
    type Output = Vec2;
    /// Applies the transform to a point (same as [`Transform::apply`]).
    #[inline]
    fn mul(self, v: Vec2) -> Vec2 {
        self.apply(v)
    }
}

/// Solves the symmetric 2×2 system `[k11 k12; k12 k22] x = b`, returning zero
/// for a singular matrix (never NaN).
// Always inlined: the joint rows call it in their innermost loop (a call
// per joint per iteration showed as 3% of joint_grid's step).
#[inline(always)]
pub fn solve22(k11: Real, k12: Real, k22: Real, b: Vec2) -> Vec2 {
    let det = k11 * k22 - k12 * k12;
    if det.abs() <= EPSILON * (k11.abs() * k22.abs()).max(EPSILON) || det == 0.0 {
        return Vec2::ZERO;
    }
    let inv_det = 1.0 / det;
    Vec2::new(
        inv_det * (k22 * b.x - k12 * b.y),
        inv_det * (k11 * b.y - k12 * b.x),
    )
}

/// A 3×3 matrix in row-major order, used for coupled constraint blocks.
pub type Mat3 = [[Real; 3]; 3];

/// Relative pivot tolerance of [`solve33_psd`] (dimensionless, usual
/// `16 ε`): a pivot of the Jacobi-scaled matrix (unit diagonal) below this
/// is round-off of an exactly singular matrix and its component is set to
/// zero.
pub const PIVOT_TOLERANCE: Real = 16.0 * EPSILON;

/// Solves `k x = b` for a symmetric positive semi-definite 3×3 `k`, never
/// NaN.
///
/// `k` is Jacobi-scaled to a unit diagonal (a zero diagonal gives a zero
/// row and `x_i = 0`), then factored as `L D Lᵀ` with pivots below
/// [`PIVOT_TOLERANCE`] treated as zero. The tolerance is relative to each
/// row's own diagonal, so badly conditioned but regular matrices (masses
/// spanning many orders of magnitude) are solved, and singular ones give a
/// solution of their well-posed part.
pub fn solve33_psd(k: &Mat3, b: [Real; 3]) -> [Real; 3] {
    let mut d = [0.0 as Real; 3];
    for i in 0..3 {
        if k[i][i] > 0.0 && k[i][i].is_finite() {
            d[i] = 1.0 / k[i][i].sqrt();
        }
    }
    // The scaled matrix `D K D` (unit diagonal) and right-hand side `D b`.
    let mut a: Mat3 = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            a[i][j] = d[i] * k[i][j] * d[j];
        }
    }
    let rhs = [d[0] * b[0], d[1] * b[1], d[2] * b[2]];
    // L D Lᵀ, L unit lower-triangular.
    let mut l: Mat3 = [[0.0; 3]; 3];
    let mut pivot = [0.0 as Real; 3];
    let mut live = [false; 3];
    for j in 0..3 {
        let mut p = a[j][j];
        for m in 0..j {
            p -= l[j][m] * l[j][m] * pivot[m];
        }
        pivot[j] = p;
        live[j] = a[j][j] > 0.0 && p > PIVOT_TOLERANCE;
        for i in (j + 1)..3 {
            let mut v = a[i][j];
            for m in 0..j {
                v -= l[i][m] * l[j][m] * pivot[m];
            }
            l[i][j] = if live[j] { v / p } else { 0.0 };
        }
    }
    // L y = rhs, z = D⁻¹ y, Lᵀ x = z.
    let mut y = [0.0 as Real; 3];
    for i in 0..3 {
        let mut v = rhs[i];
        for m in 0..i {
            v -= l[i][m] * y[m];
        }
        y[i] = v;
    }
    let mut x = [0.0 as Real; 3];
    for i in (0..3).rev() {
        let mut v = if live[i] { y[i] / pivot[i] } else { 0.0 };
        for m in (i + 1)..3 {
            v -= l[m][i] * x[m];
        }
        x[i] = v;
    }
    [d[0] * x[0], d[1] * x[1], d[2] * x[2]]
}

/// `atan2(y, x)` for the solver's angle reads ([`Rot::relative_angle`]:
/// every joint angle row, every iteration), in `[−π, π]` with the signs
/// of `f64::atan2` at zeros.
///
/// In the f32 build it is a polynomial, not the C library's `atan2f`
/// (which took about 8% of a ragdoll scene's step): one division, a
/// degree-9 odd polynomial in Estrin's form (short dependency chains), and
/// reflections by selects. With `lo = min(|x|, |y|)`, `hi = max(|x|, |y|)`:
///
/// ```text
///   lo ≤ tan(π/8) hi:  u = lo / hi                a = atan u
///   otherwise:         u = (lo − hi) / (lo + hi)  a = π/4 + atan u
///                      (atan(t) − π/4 = atan((t − 1)/(t + 1)), t = lo/hi)
///   atan u ≈ u (c0 + c1 u² + c2 u⁴ + c3 u⁶ + c4 u⁸),  |u| ≤ tan(π/8):
///            minimax (Lawson's reweighted least squares), 3.5e-9 rad
///   |y| > |x|:  a = π/2 − a;   x < 0:  a = π − a;   y < 0:  a = −a
///   (copysign, so −0 gives −π and −0 as the library does)
/// ```
///
/// Worst error 3.0e-7 rad (rounding, mostly the reflections' half ulps
/// near π), against 1.2e-7 for `atan2f`. The same operations in the same
/// order on every machine (no FMA, no library call). In the f64 build it
/// is `f64::atan2`.
#[inline]
#[must_use]
pub fn solver_atan2(y: Real, x: Real) -> Real {
    #[cfg(feature = "f64")]
    {
        y.atan2(x)
    }
    #[cfg(not(feature = "f64"))]
    {
        use atan2_terms::{C0, C1, C2, C3, C4, TAN_PI_8};
        use core::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
        let (ax, ay) = (x.abs(), y.abs());
        let steep = ay > ax;
        let (lo, hi) = if steep { (ax, ay) } else { (ay, ax) };
        if !(hi > 0.0 && hi.is_finite()) {
            // Both zero (or not finite): the library's answer.
            return y.atan2(x);
        }
        let past_eighth = lo > TAN_PI_8 * hi;
        let (num, den) = if past_eighth {
            (lo - hi, lo + hi)
        } else {
            (lo, hi)
        };
        let u = num / den;
        let z = u * u;
        let z2 = z * z;
        let p = (C0 + C1 * z) + z2 * ((C2 + C3 * z) + z2 * C4);
        let mut a = p * u;
        if past_eighth {
            a += FRAC_PI_4;
        }
        if steep {
            a = FRAC_PI_2 - a;
        }
        if x < 0.0 {
            a = PI - a;
        }
        a.copysign(y)
    }
}

/// The constants of [`solver_atan2`]'s f32 polynomial, for a version of
/// it over other number types that must agree with it bit for bit (the
/// revolute joints' lanes, `janus2d_constraints`).
#[cfg(not(feature = "f64"))]
pub mod atan2_terms {
    /// tan(π/8): past it, the argument is reduced by π/4.
    pub const TAN_PI_8: f32 = 0.414_213_57;
    /// Coefficient of u (dimensionless).
    pub const C0: f32 = 0.999_999_9;
    /// Coefficient of u³.
    pub const C1: f32 = -0.333_322_05;
    /// Coefficient of u⁵.
    pub const C2: f32 = 0.199_619_65;
    /// Coefficient of u⁷.
    pub const C3: f32 = -0.137_548_06;
    /// Coefficient of u⁹.
    pub const C4: f32 = 0.077_345_36;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The solver's atan2 against f64's over a million directions, at unit
    /// length and at scales from 1e-20 to 1e20: within 3.0e-7 rad (f32:
    /// the polynomial's 3.5e-9, its evaluation, and half an ulp for each of
    /// the three reflections, 3e-8 at π/4, 6e-8 at π/2, 1.2e-7 at π);
    /// exact in the f64 build.
    #[test]
    fn solver_atan2_is_within_its_error_bound_everywhere() {
        let bound = if cfg!(feature = "f64") { 0.0 } else { 3.0e-7 };
        let mut worst: f64 = 0.0;
        let n = 1_000_000;
        for i in 0..n {
            let theta = -std::f64::consts::PI + std::f64::consts::TAU * (i as f64 + 0.5) / n as f64;
            for scale in [1.0, 1e-20, 1e20] {
                let (y, x) = ((theta.sin() * scale) as Real, (theta.cos() * scale) as Real);
                // The f64 build's reference is its own atan2 (the same
                // call); the f32 build's, f64's of the same input.
                let exact = to_f64(y).atan2(to_f64(x));
                let got = to_f64(solver_atan2(y, x));
                let err = (got - exact).abs();
                worst = worst.max(err);
            }
        }
        if std::env::var("JANUS2D_REPORT").is_ok() {
            eprintln!("solver_atan2: worst error {worst:e} rad (bound {bound:e})");
        }
        assert!(worst <= bound, "worst error {worst:e} rad > {bound:e}");
    }

    /// The signs and axes match the library's: zeros of either sign, the
    /// four axes, the diagonals, and non-finite input.
    #[test]
    fn solver_atan2_keeps_the_signs_at_zeros_and_axes() {
        for (y, x) in [
            (0.0, 1.0),
            (-0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (1.0, -0.0),
            (0.0, 0.0),
            (-0.0, 0.0),
            (0.0, -0.0),
            (-0.0, -0.0),
        ] {
            let (y, x): (Real, Real) = (y, x);
            let got = solver_atan2(y, x);
            let want = y.atan2(x);
            assert!(
                (got - want).abs() <= 3.0e-7 && got.is_sign_negative() == want.is_sign_negative(),
                "atan2({y}, {x}) = {got}, library {want}"
            );
        }
        for (y, x) in [(1.0, 1.0), (1.0, -1.0), (-1.0, -1.0), (-1.0, 1.0)] {
            let (y, x): (Real, Real) = (y, x);
            assert!((solver_atan2(y, x) - y.atan2(x)).abs() <= 3.0e-7);
        }
        assert!(solver_atan2(Real::NAN, 1.0).is_nan());
        assert!(solver_atan2(1.0, Real::NAN).is_nan());
    }

    #[test]
    fn wrap_angle_fast_path_matches_round() {
        // Every angle within 1.5 turns, densely, and the ties at ±π.
        let mut x: Real = -9.4;
        while x < 9.4 {
            let slow = x - TAU * (x / TAU).round();
            assert_eq!(wrap_angle(x).to_bits(), slow.to_bits(), "x = {x}");
            x += 0.000_37;
        }
        for x in [PI, -PI, 3.0 * PI, -3.0 * PI, 100.0, -1e6] {
            let slow = x - TAU * (x / TAU).round();
            assert_eq!(wrap_angle(x).to_bits(), slow.to_bits(), "x = {x}");
        }
        assert!(wrap_angle(Real::NAN).is_nan());
    }

    /// The comparison `|x| < π` that skips the division: every float within
    /// 100,000 steps of ±π (and of 0) wraps bit for bit as the round formula
    /// does: the float just below π to itself, π to −π and −π to π (half
    /// away from zero).
    #[test]
    fn wrap_angle_without_a_division_inside_half_a_turn() {
        for centre in [PI, -PI, 0.0] {
            let mut x = centre;
            let mut y = centre;
            for _ in 0..100_000 {
                for v in [x, y] {
                    let slow = v - TAU * (v / TAU).round();
                    assert_eq!(wrap_angle(v).to_bits(), slow.to_bits(), "x = {v:e}");
                }
                x = x.next_up();
                y = y.next_down();
            }
        }
        assert_eq!(wrap_angle(PI.next_down()), PI.next_down());
        assert_eq!(wrap_angle(PI), -PI);
        assert_eq!(wrap_angle(-PI), PI);
    }

    #[test]
    fn rot_inverse_roundtrip() {
        let q = Rot::from_angle(0.7);
        let v = Vec2::new(1.5, -2.0);
        let back = q.inv_rotate(q.rotate(v));
        assert!((back - v).length() < 1e-5);
        assert!((q.relative_angle(Rot::from_angle(1.0)) - 0.3).abs() < 1e-5);
    }

    #[test]
    fn wrap_angle_maps_two_pi_to_zero() {
        assert!(wrap_angle(TAU).abs() < 1e-5);
        assert!(wrap_angle(-TAU).abs() < 1e-5);
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-5);
    }

    #[test]
    fn solve33_matches_direct_solution() {
        let k: Mat3 = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        let b = [1.0, 2.0, 3.0];
        let x = solve33_psd(&k, b);
        for i in 0..3 {
            let r = k[i][0] * x[0] + k[i][1] * x[1] + k[i][2] * x[2];
            assert!((r - b[i]).abs() < 1e-5, "row {i}: {r} vs {}", b[i]);
        }
    }

    #[test]
    fn solve33_singular_is_finite() {
        let k: Mat3 = [[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 0.0]];
        let x = solve33_psd(&k, [1.0, 1.0, 1.0]);
        assert!(x.iter().all(|v| v.is_finite()));
        assert!(((x[0] + x[1]) - 1.0).abs() < 1e-5);
        assert_eq!(x[2], 0.0);
    }
}
