//! Lane types: the numbers the contact rows are written over.
//!
//! The contact rows ([`crate::contact_row`]) are written once, generic over
//! a [`Lane`]: one contact at a time on [`Real`] (the scalar overflow and the
//! light clusters' groups), [`LANES`] contacts at a time on [`Wide`]
//! (`wide::f32x8`, or `wide::f64x4` with the `f64` feature: SIMD without
//! `unsafe`) in the colours' chunks. The trait has exactly the operations
//! the rows use; each is one instruction on either type, with the same
//! result lane by lane:
//!
//! | operation              | `Real`                       | `Wide`                    |
//! |------------------------|------------------------------|---------------------------|
//! | `+ − × ÷`, `+= −=`     | the float's                  | lane-wise                 |
//! | `−x`                   | sign flip                    | `0 − x` (as `wide` does)  |
//! | [`Lane::at_least`]     | `if x > lo { x } else { lo }`| `max` instruction         |
//! | [`Lane::at_most`]      | `if x < hi { x } else { hi }`| `min` instruction         |
//! | comparisons            | `bool`                       | all-ones lane masks       |
//! | [`Lane::select`]       | `if`                         | blend                     |
//! | [`Lane::abs`]          | sign bit cleared             | sign bits cleared         |
//! | [`Lane::flip_sign`]    | `−x`                         | sign bits flipped         |
//! | [`Lane::sqrt`]         | `sqrt`                       | lane-wise `sqrt`          |
//!
//! `at_least` and `at_most` return their argument where `x` is NaN (the
//! `max` and `min` instructions of SSE do); `−x` differs between the two
//! only in the sign of a zero (`−(+0) = −0` on `Real`, `0 − (+0) = +0` on
//! `Wide`).

use std::fmt::Debug;
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, Neg, Sub, SubAssign};

use janus2d_core::body::BodyState;
use janus2d_core::math::{Real, Vec2};
use wide::{CmpEq, CmpGe, CmpGt, CmpLt, CmpNe};

/// Lanes of [`Wide`].
#[cfg(not(feature = "f64"))]
pub const LANES: usize = 8;
/// Lanes of [`Wide`].
#[cfg(feature = "f64")]
pub const LANES: usize = 4;

/// The SIMD lane type: [`LANES`] values of [`Real`].
#[cfg(not(feature = "f64"))]
pub type Wide = wide::f32x8;
/// The SIMD lane type: [`LANES`] values of [`Real`].
#[cfg(feature = "f64")]
pub type Wide = wide::f64x4;

/// A number the contact rows are computed on: one [`Real`] or [`LANES`] of
/// them ([`Wide`]). See the module docs for what each operation is.
pub trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + Debug
    + PartialEq
{
    /// The result of a comparison: `bool`, or a lane mask.
    type Mask: Copy + BitAnd<Output = Self::Mask> + BitOr<Output = Self::Mask> + Debug + PartialEq;

    /// `x` in every lane.
    fn splat(x: Real) -> Self;
    /// `self` where it is greater than `lo`, else `lo` (also for a NaN
    /// `self`).
    fn at_least(self, lo: Self) -> Self;
    /// `self` where it is less than `hi`, else `hi` (also for a NaN
    /// `self`).
    fn at_most(self, hi: Self) -> Self;
    /// `self > other`.
    fn gt(self, other: Self) -> Self::Mask;
    /// `self < other`.
    fn lt(self, other: Self) -> Self::Mask;
    /// `self ≥ other`.
    fn ge(self, other: Self) -> Self::Mask;
    /// `self = other`.
    fn eq(self, other: Self) -> Self::Mask;
    /// `self ≠ other` (true where either is NaN).
    fn ne(self, other: Self) -> Self::Mask;
    /// `on_true` where `mask` holds, else `on_false`.
    fn select(mask: Self::Mask, on_true: Self, on_false: Self) -> Self;
    /// `|self|` (the sign bit cleared, NaN included).
    fn abs(self) -> Self;
    /// `−self` by its sign bit, as the float's own negation (`−(+0) = −0`,
    /// where the operator on `Wide` gives `0 − x`).
    fn flip_sign(self) -> Self;
    /// `√self` (correctly rounded on either type).
    fn sqrt(self) -> Self;
    /// Whether `mask` holds in some lane.
    fn any(mask: Self::Mask) -> bool;
    /// Lane `k`'s value (`k = 0` for [`Real`]).
    fn lane(&self, k: usize) -> Real;
    /// Sets lane `k` to `x` (`k = 0` for [`Real`]).
    fn set_lane(&mut self, k: usize, x: Real);

    /// `self` clamped to `[lo, hi]`: `self.at_least(lo).at_most(hi)`.
    #[inline(always)]
    fn clamp_to(self, lo: Self, hi: Self) -> Self {
        self.at_least(lo).at_most(hi)
    }
}

impl Lane for Real {
    type Mask = bool;

    #[inline(always)]
    fn splat(x: Real) -> Self {
        x
    }
    #[inline(always)]
    fn at_least(self, lo: Self) -> Self {
        if self > lo { self } else { lo }
    }
    #[inline(always)]
    fn at_most(self, hi: Self) -> Self {
        if self < hi { self } else { hi }
    }
    #[inline(always)]
    fn gt(self, other: Self) -> bool {
        self > other
    }
    #[inline(always)]
    fn lt(self, other: Self) -> bool {
        self < other
    }
    #[inline(always)]
    fn ge(self, other: Self) -> bool {
        self >= other
    }
    #[inline(always)]
    fn eq(self, other: Self) -> bool {
        self == other
    }
    #[inline(always)]
    fn ne(self, other: Self) -> bool {
        self != other
    }
    #[inline(always)]
    fn select(mask: bool, on_true: Self, on_false: Self) -> Self {
        if mask { on_true } else { on_false }
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Real::abs(self)
    }
    #[inline(always)]
    fn flip_sign(self) -> Self {
        -self
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Real::sqrt(self)
    }
    #[inline(always)]
    fn any(mask: bool) -> bool {
        mask
    }
    #[inline(always)]
    fn lane(&self, k: usize) -> Real {
        debug_assert_eq!(k, 0);
        *self
    }
    #[inline(always)]
    fn set_lane(&mut self, k: usize, x: Real) {
        debug_assert_eq!(k, 0);
        *self = x;
    }
}

impl Lane for Wide {
    type Mask = Wide;

    #[inline(always)]
    fn splat(x: Real) -> Self {
        Wide::splat(x)
    }
    #[inline(always)]
    fn at_least(self, lo: Self) -> Self {
        self.fast_max(lo)
    }
    #[inline(always)]
    fn at_most(self, hi: Self) -> Self {
        self.fast_min(hi)
    }
    #[inline(always)]
    fn gt(self, other: Self) -> Wide {
        self.cmp_gt(other)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> Wide {
        self.cmp_lt(other)
    }
    #[inline(always)]
    fn ge(self, other: Self) -> Wide {
        self.cmp_ge(other)
    }
    #[inline(always)]
    fn eq(self, other: Self) -> Wide {
        self.cmp_eq(other)
    }
    #[inline(always)]
    fn ne(self, other: Self) -> Wide {
        self.cmp_ne(other)
    }
    #[inline(always)]
    fn select(mask: Wide, on_true: Self, on_false: Self) -> Self {
        mask.blend(on_true, on_false)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Wide::abs(self)
    }
    #[inline(always)]
    fn flip_sign(self) -> Self {
        self ^ Wide::splat(-0.0)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Wide::sqrt(self)
    }
    #[inline(always)]
    fn any(mask: Wide) -> bool {
        mask.any()
    }
    #[inline(always)]
    fn lane(&self, k: usize) -> Real {
        self.as_array_ref()[k]
    }
    #[inline(always)]
    fn set_lane(&mut self, k: usize, x: Real) {
        self.as_array_mut()[k] = x;
    }
}

/// A vector per lane: `x` and `y` on [`Real`] (one vector) or on the wide
/// lane type ([`LANES`](crate::lane::LANES) vectors). Its operations are
/// glam's on [`Vec2`], component by component, so a lane computes what the
/// one-vector form computes, bit for bit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct V2<L> {
    pub(crate) x: L,
    pub(crate) y: L,
}

impl<L: Lane> V2<L> {
    #[inline(always)]
    pub(crate) fn new(x: L, y: L) -> Self {
        V2 { x, y }
    }
    /// `(0, 0)` in every lane.
    #[inline(always)]
    pub(crate) fn zero() -> Self {
        V2::new(L::splat(0.0), L::splat(0.0))
    }
    #[inline(always)]
    pub(crate) fn add(self, o: Self) -> Self {
        V2::new(self.x + o.x, self.y + o.y)
    }
    #[inline(always)]
    pub(crate) fn sub(self, o: Self) -> Self {
        V2::new(self.x - o.x, self.y - o.y)
    }
    /// `k · self`.
    #[inline(always)]
    pub(crate) fn scale(self, k: L) -> Self {
        V2::new(k * self.x, k * self.y)
    }
    /// `self` where `mask` holds, else `other`.
    #[inline(always)]
    pub(crate) fn select(mask: L::Mask, on_true: Self, on_false: Self) -> Self {
        V2::new(
            L::select(mask, on_true.x, on_false.x),
            L::select(mask, on_true.y, on_false.y),
        )
    }
}

impl From<Vec2> for V2<Real> {
    #[inline(always)]
    fn from(v: Vec2) -> Self {
        V2::new(v.x, v.y)
    }
}

impl From<V2<Real>> for Vec2 {
    #[inline(always)]
    fn from(v: V2<Real>) -> Self {
        Vec2::new(v.x, v.y)
    }
}

/// The velocities of one side of a constraint's lanes (of the contact
/// rows, of a point block): one body's on [`Real`], [`LANES`] bodies' on
/// [`Wide`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Velocity<L> {
    /// Linear velocity, x, m/s.
    pub(crate) v_x: L,
    /// Linear velocity, y, m/s.
    pub(crate) v_y: L,
    /// Angular velocity, rad/s.
    pub(crate) w: L,
}

/// The position deltas of one side since the start of the step.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Delta<L> {
    /// Position delta, x, m.
    pub(crate) dp_x: L,
    /// Position delta, y, m.
    pub(crate) dp_y: L,
    /// Rotation delta, cosine.
    pub(crate) q_c: L,
    /// Rotation delta, sine.
    pub(crate) q_s: L,
}

impl Velocity<Real> {
    /// A state's velocities.
    #[inline(always)]
    pub(crate) fn of(s: &BodyState) -> Self {
        Velocity {
            v_x: s.v.x,
            v_y: s.v.y,
            w: s.w,
        }
    }

    /// Writes the velocities into a state.
    #[inline(always)]
    pub(crate) fn store(&self, s: &mut BodyState) {
        s.v = Vec2::new(self.v_x, self.v_y);
        s.w = self.w;
    }
}

impl Delta<Real> {
    /// A state's position deltas.
    #[inline(always)]
    pub(crate) fn of(s: &BodyState) -> Self {
        Delta {
            dp_x: s.dp.x,
            dp_y: s.dp.y,
            q_c: s.dq.c,
            q_s: s.dq.s,
        }
    }
}

impl<L: Lane> Velocity<L> {
    /// The linear velocity as a vector per lane, m/s.
    #[inline(always)]
    pub(crate) fn v(&self) -> V2<L> {
        V2::new(self.v_x, self.v_y)
    }

    /// Sets the linear velocity, m/s.
    #[inline(always)]
    pub(crate) fn set_v(&mut self, v: V2<L>) {
        self.v_x = v.x;
        self.v_y = v.y;
    }

    /// `on_true` where `mask` holds, else `on_false`.
    #[inline(always)]
    pub(crate) fn select(mask: L::Mask, on_true: Self, on_false: Self) -> Self {
        Velocity {
            v_x: L::select(mask, on_true.v_x, on_false.v_x),
            v_y: L::select(mask, on_true.v_y, on_false.v_y),
            w: L::select(mask, on_true.w, on_false.w),
        }
    }
}

/// [`solver_atan2`](janus2d_core::math::solver_atan2) lane by lane, bit
/// for bit. In the f32 build: the same polynomial and reductions in the
/// same order, its branches as selects, and `copysign` as the sign bit of
/// `y` on the magnitude; a lane where `max(|x|, |y|)` is zero or not
/// finite takes the scalar function, as the scalar function takes the
/// library's there. In the f64 build: the scalar function on each lane.
#[inline(always)]
#[must_use]
pub(crate) fn atan2_lanes(y: Wide, x: Wide) -> Wide {
    #[cfg(feature = "f64")]
    {
        let (ys, xs) = (y.to_array(), x.to_array());
        Wide::from(std::array::from_fn::<Real, LANES, _>(|k| {
            janus2d_core::math::solver_atan2(ys[k], xs[k])
        }))
    }
    #[cfg(not(feature = "f64"))]
    {
        use core::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
        use janus2d_core::math::atan2_terms::{C0, C1, C2, C3, C4, TAN_PI_8};
        let s = Wide::splat;
        let (ax, ay) = (Lane::abs(x), Lane::abs(y));
        let steep = Lane::gt(ay, ax);
        let (lo, hi) = (Wide::select(steep, ax, ay), Wide::select(steep, ay, ax));
        let past_eighth = Lane::gt(lo, s(TAN_PI_8) * hi);
        let num = Wide::select(past_eighth, lo - hi, lo);
        let den = Wide::select(past_eighth, lo + hi, hi);
        let u = num / den;
        let z = u * u;
        let z2 = z * z;
        let p = (s(C0) + s(C1) * z) + z2 * ((s(C2) + s(C3) * z) + z2 * s(C4));
        let mut a = p * u;
        a = Wide::select(past_eighth, a + s(FRAC_PI_4), a);
        a = Wide::select(steep, s(FRAC_PI_2) - a, a);
        a = Wide::select(Lane::lt(x, s(0.0)), s(PI) - a, a);
        let sign = s(-0.0);
        let mut out = Lane::abs(a) | (y & sign);
        let usual = Lane::gt(hi, s(0.0)) & Lane::lt(hi, s(Real::INFINITY));
        if !usual.all() {
            out = atan2_unusual_lanes(y, x, out, usual.move_mask());
        }
        out
    }
}

/// `out` with the lanes not in `usual` (bit `k`: lane `k`) replaced by
/// the scalar function's answer (kept out of line: no unit rotation gets
/// here).
#[cfg(not(feature = "f64"))]
#[cold]
#[inline(never)]
fn atan2_unusual_lanes(y: Wide, x: Wide, mut out: Wide, usual: i32) -> Wide {
    let (ys, xs) = (y.to_array(), x.to_array());
    for k in 0..LANES {
        if usual & (1 << k) == 0 {
            out.set_lane(k, janus2d_core::math::solver_atan2(ys[k], xs[k]));
        }
    }
    out
}

/// [`wrap_angle`](janus2d_core::math::wrap_angle) lane by lane, bit for
/// bit: lanes within `(−π, π)` as they are (its common path), the others
/// through the scalar function.
#[inline(always)]
#[must_use]
pub(crate) fn wrap_angle_lanes(x: Wide) -> Wide {
    let within = Lane::lt(Lane::abs(x), Wide::splat(janus2d_core::math::PI));
    if within.all() {
        return x;
    }
    wrap_unusual_lanes(x, within)
}

/// `x` with the lanes outside `(−π, π)` (not in `within`) wrapped by the
/// scalar function (out of line: a joint angle rarely gets here).
#[cold]
#[inline(never)]
fn wrap_unusual_lanes(x: Wide, within: Wide) -> Wide {
    let mut out = x;
    for k in 0..LANES {
        if within.lane(k).to_bits() == 0 {
            out.set_lane(k, janus2d_core::math::wrap_angle(x.lane(k)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lane versions of `solver_atan2` and `wrap_angle` give the
    /// scalar functions' bits on every lane: random pairs of every size
    /// and sign, the axes and diagonals, signed zeros, infinities and NaN,
    /// and angles around ±π and far past them.
    #[test]
    fn angle_lanes_match_the_scalar_functions_bit_for_bit() {
        use janus2d_core::math::{solver_atan2, wrap_angle};
        let mut seed = 0x2545_f491_u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((seed >> 33) as f64 / (1u64 << 31) as f64 * 2.0 - 1.0) as Real
        };
        let specials: [Real; 12] = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            1e-30,
            -1e-30,
            1e30,
            Real::INFINITY,
            Real::NEG_INFINITY,
            Real::NAN,
            0.414_213_57,
            -0.707_106_77,
        ];
        let mut pairs = Vec::new();
        for &y in &specials {
            for &x in &specials {
                pairs.push((y, x));
            }
        }
        for _ in 0..20_000 {
            let scale = [1e-3, 1.0, 1e3][pairs.len() % 3];
            pairs.push((scale * next(), scale * next()));
        }
        for block in pairs.chunks(LANES) {
            let mut ys = [0.0; LANES];
            let mut xs = [1.0; LANES];
            for (k, &(y, x)) in block.iter().enumerate() {
                (ys[k], xs[k]) = (y, x);
            }
            let got = atan2_lanes(Wide::from(ys), Wide::from(xs)).to_array();
            for k in 0..LANES {
                let want = solver_atan2(ys[k], xs[k]);
                assert!(
                    got[k].to_bits() == want.to_bits() || (got[k].is_nan() && want.is_nan()),
                    "atan2({}, {}): {} against {want}",
                    ys[k],
                    xs[k],
                    got[k]
                );
            }
            // Angles from −4π to 4π, most within (−π, π).
            let angles: [Real; LANES] = std::array::from_fn(|k| ys[k] * 4.0 + xs[k] * 0.1);
            let wrapped = wrap_angle_lanes(Wide::from(angles)).to_array();
            for k in 0..LANES {
                let want = wrap_angle(angles[k]);
                assert!(
                    wrapped[k].to_bits() == want.to_bits()
                        || (want.is_nan() && wrapped[k].is_nan()),
                    "wrap({}): {} against {want}",
                    angles[k],
                    wrapped[k]
                );
            }
        }
    }

    /// Each operation gives the same value on `Real` as lane by lane on
    /// `Wide`, NaN included.
    #[test]
    fn real_and_wide_agree_lane_by_lane() {
        let xs: [Real; 8] = [-2.0, -0.5, 0.0, 0.5, 1.0, 3.0, Real::NAN, Real::INFINITY];
        let (lo, hi) = (-0.5, 1.0);
        for x in xs {
            let w = Wide::splat(x);
            let lane0 = |v: Wide| v.to_array()[0];
            let same = |a: Real, b: Real| a.to_bits() == b.to_bits();
            assert!(same(x.at_least(lo), lane0(w.at_least(Wide::splat(lo)))));
            assert!(same(x.at_most(hi), lane0(w.at_most(Wide::splat(hi)))));
            assert!(same(
                x.clamp_to(lo, hi),
                lane0(w.clamp_to(Wide::splat(lo), Wide::splat(hi)))
            ));
            let mask = <Wide as Lane>::gt(w, Wide::splat(0.0));
            assert_eq!(Lane::gt(x, 0.0), <Wide as Lane>::any(mask));
            assert!(same(
                Real::select(Lane::gt(x, 0.0), 1.0, 2.0),
                lane0(Wide::select(mask, Wide::splat(1.0), Wide::splat(2.0)))
            ));
        }
    }
}
